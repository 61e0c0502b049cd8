"""`python3 -m mbot_follower.metrics OUTPUT_DIR`: print the summary of a run folder."""
import sys

from mbot_follower.metrics import main

sys.exit(main())
