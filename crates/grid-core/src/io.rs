//! ROS map_server I/O. Filled in by the I/O work.
