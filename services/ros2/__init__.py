"""ROS 2 over rmw_zenoh: the wire (keys, attachments, liveliness, CDR), pure conversions
between ROS 2 and zenav messages, and a thin ROS 2 node on zenav's bus."""
