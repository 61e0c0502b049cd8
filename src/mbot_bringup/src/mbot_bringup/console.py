"""The scenario runner's messages: one bold [mbot] line each on stderr."""
import sys


def say(text):
    sys.stderr.write("\033[1m[mbot]\033[0m %s\n" % text)
    sys.stderr.flush()
