"""mbot_sim: Python helpers of the simulator (the simulator itself is the C++ stage_node)."""
