"""The simulator that stands in for the robot hardware."""

from pathlib import Path

SCENARIO_DIR = Path(__file__).resolve().parent / "scenarios"
"""The shipped scenarios (the paper's eight cases and experiments); installed with the package."""
