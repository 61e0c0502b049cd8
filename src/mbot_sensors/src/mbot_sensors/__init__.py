"""mbot_sensors: tools for the robots' sensors (the IMU's Allan variance)."""
