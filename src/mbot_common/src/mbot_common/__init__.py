"""mbot_common: ROS-free basics shared by every mbot package (see the package README).

    geometry     Pose2D, Twist2D, normalize_angle, yaw_of, compose / inverse / relative
    strict_yaml  ConfigError, load_yaml, Reader (strict config files)
    maps         MapData, load_map (map_server yaml + PGM)
    world        World, load_world (world files, as strict as stage_node)
    paths        find_maps_directory, resolve_world, resolve_map
    params       get_param, read_params (strict rospy parameters; rospy imported on use)
"""
