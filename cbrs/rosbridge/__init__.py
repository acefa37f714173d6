"""A rosbridge v2 server without ROS: topics, services and parameters for non-ROS nodes and web pages."""
