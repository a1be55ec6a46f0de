"""ROS-free evaluation of the model against motion capture (Table I metrics, never imports rclpy)."""
