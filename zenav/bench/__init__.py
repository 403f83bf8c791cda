"""The benchmarks (results in ``docs/benchmarks.md``).

- ``zenav bench perf`` (:mod:`.perf`): compute per scan (:mod:`.compute`), latency over
  Zenoh (:mod:`.latency`), memory (:mod:`.memory`), lockstep speed (:mod:`.lockstep`) and
  sustained scan rate (:mod:`.rate`); the live stack they listen to is :mod:`.live`;
- ``zenav bench nav`` (:mod:`.nav`): the planners on seeded random worlds;
- ``zenav bench crowd`` (:mod:`.crowd`): CrowdNav's test protocol, every planner;
- ``zenav bench accuracy`` (:mod:`.tracking_accuracy`, also ``python -m
  zenav.bench.tracking_accuracy``): obstacle typing, speed and heading errors;
- ``zenav soak`` (:mod:`.soak`): the stack in real time for a long time.

:mod:`.common` holds what they share; :mod:`.cli` registers the commands.
"""
