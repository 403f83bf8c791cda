"""Baseline local planners for the navigation benchmark: VFH, DWA, an artificial
potential field, and ORCA (CrowdNav's own baseline). Each is a pure module (numpy in,
(v, omega) out) and a thin planner node that reads the same inputs and publishes the same
outputs as the paper's planner, selected with ``zenav run --planner vfh|dwa|apf|orca``."""
