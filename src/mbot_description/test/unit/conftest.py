# pytest loads this first: paths.py puts the package's src/ on sys.path.
import paths  # noqa: F401
