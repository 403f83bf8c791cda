"""``zenav monitor``: a live, read-only view of a running stack, from any host.

Modules: :mod:`.model` (what the monitor knows), :mod:`.view` (the map round the robot in
characters), :mod:`.screen` (the terminal view), :mod:`.command` (the process and
``zenav monitor``).

:class:`MonitorModel` is what the monitor knows, fed with (key, payload, receive time)
and liveliness changes; it has no I/O and is tested without a terminal. The screen
(:func:`render`, with ``rich``) and the JSON-lines output (``--jsonl``, for scripts and
tests) both read it.

What it tracks:

- the robot: pose and speed from odometry; speed in ground truth too when a simulator
  publishes it; the last base command and why (``command``, ``stale``, ``idle``);
- the obstacles: the latest track list, with type, speed and heading;
- the planner: the current scenario letter and action, the latest decision;
- the planner's global path (``planner/path``, sent when it plans again or finds no
  way, and repeated about once a second): length, waypoints, why and when it was planned,
  how long ago it was last heard, how many distinct paths were heard (a repeat is not
  another), and the robot's distance to go along it and off it; and its occupancy map
  (``planner/map``, about once a second): size, resolution, the known and occupied
  shares of its cells, its age. The screen draws both round the robot in characters
  (:mod:`.view`); ``--jsonl`` snapshots carry the path's vertices and the map's figures,
  not its cells;
- each service's liveliness token, with restarts counted, and its status counters;
- the rate of every topic, and when a topic stops or starts flowing;
- scan-to-command latency: for a scan with stamp ``s``, the wall time between the
  monitor receiving that scan and receiving the velocity command stamped ``s``. Both
  receive times are taken in the same process (in Zenoh's callback), so no clock
  synchronisation is needed; the figure includes the monitor's own receive path for the
  command, which on one host is tens of microseconds.

Events (``drain_events``) are state changes with the wall time they happened:
``alive`` (a token appeared or went), ``flow`` (a topic stopped or started), ``base``
(the base command's reason changed, e.g. to ``stale``), ``motion`` (the robot started or
came to a standstill), ``planner`` (scenario or action changed), ``decision`` (a planner
event), ``path`` (a new global path heard, not a repeat: why, waypoints, length, the stamp
it was planned at), ``result`` (the simulated run ended).
"""
