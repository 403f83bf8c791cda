"""The simulator that stands in for the robot hardware."""
