"""Laser driver: turns a device's raw frames into validated laser scans."""
