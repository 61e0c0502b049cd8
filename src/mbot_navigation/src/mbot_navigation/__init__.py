"""Python side of mbot_navigation: the fleet launcher (fleet_launch) and the navigation trial
benchmark (nav_trial). The navigation itself is C++ (nav_node)."""
