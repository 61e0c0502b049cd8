"""mbot_description: robot models of the mbot fleet and per-robot URDF prefixing."""
