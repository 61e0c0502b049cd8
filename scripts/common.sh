# Shared by scripts/setup, test, demo, bench: where things are and how to get a ROS shell.
# Sourced, not run. Works from a plain shell: ROS Python is /usr/bin/python3, so /usr/bin
# goes first on PATH (a pyenv or venv python3 earlier on PATH has no rospy).

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export PYTHONDONTWRITEBYTECODE=1
OUT="$ROOT/out"              # reports, test results, benchmark JSON

say() { printf '\033[1m[mbot]\033[0m %s\n' "$*" >&2; }
die() { say "error: $*"; exit 1; }

# "debian" (Debian 12, ROS 1 from Debian's packages) or "noetic" (Ubuntu 20.04 + /opt/ros/noetic).
platform() {
  if [ -f /opt/ros/noetic/setup.bash ]; then echo noetic; return; fi
  . /etc/os-release
  case "$ID" in
    debian) echo debian ;;
    *) die "unsupported system '$PRETTY_NAME': use Debian 12, or Ubuntu 20.04 with ROS Noetic" ;;
  esac
}

as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

# Source the ROS environment of the system, then of the workspace if it is built.
ros_env() {
  set +u
  if [ -f /opt/ros/noetic/setup.bash ]; then . /opt/ros/noetic/setup.bash; fi
  if [ -f "$ROOT/devel/setup.bash" ]; then . "$ROOT/devel/setup.bash"; fi
  set -u
}

# A private ROS master for this run, on a free port, so that runs never share a master.
free_port() {
  /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

# catkin.yaml -> shell variables BUILD_TYPE, JOBS, CMAKE_ARGS, PACKAGES;
# use as: eval "$(catkin_settings)"
catkin_settings() {
  /usr/bin/python3 - "$ROOT/catkin.yaml" <<'PY'
import shlex, sys, yaml
cfg = yaml.safe_load(open(sys.argv[1]))
allowed = {"build_type", "cmake_args", "jobs", "packages"}
unknown = set(cfg) - allowed
if unknown:
    sys.exit("catkin.yaml: unknown key(s) %s; expected %s" % (sorted(unknown), sorted(allowed)))
print("BUILD_TYPE=%s" % cfg["build_type"])
print("JOBS=%d" % int(cfg["jobs"]))
print("CMAKE_ARGS=%s" % shlex.quote(" ".join(cfg.get("cmake_args", []))))
print("PACKAGES=%s" % shlex.quote(" ".join(cfg["packages"])))
PY
}

# Start a virtual X display for rviz (Mesa software GL); sets DISPLAY and XVFB_PID.
start_xvfb() {
  local fdfile
  fdfile=$(mktemp)
  Xvfb -displayfd 3 -screen 0 1200x846x24 -nolisten tcp 3>"$fdfile" >/dev/null 2>&1 &
  XVFB_PID=$!
  for _ in $(seq 100); do [ -s "$fdfile" ] && break; sleep 0.1; done
  [ -s "$fdfile" ] || die "Xvfb did not start"
  export DISPLAY=":$(cat "$fdfile")"
  export LIBGL_ALWAYS_SOFTWARE=1
  rm -f "$fdfile"
}
