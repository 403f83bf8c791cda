"""Motor bridge: velocity commands to base commands, within limits, stopping on stale input."""
