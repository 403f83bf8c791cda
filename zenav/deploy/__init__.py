"""Long-running stacks under supervisord: ``zenav up``, ``zenav down``, ``zenav ctl``.

A *deployment file* (``deploy/stack.yaml``, ``deploy/robot.yaml``, ``deploy/server.yaml``)
says which services run on this host, with which parameter files, how they join the
bus, and whether this host runs the Zenoh router. ``zenav up`` turns it into a
supervisord configuration in a run directory, starts supervisord, and returns once every
program is running and every service's liveliness token is on the bus. supervisord then
restarts any program that dies (``kill -9`` included), keeps one log per program, and
stops them all in order on ``zenav down``.

Run directory (default ``~/.local/state/zenav/<name>``, or ``--run-dir``)::

    supervisord.conf     generated; `supervisorctl -c` it, or use `zenav ctl`
    supervisord.pid      supervisord.log is in logs/
    transport.yaml       how the services join (client of the router)
    params/              parameters derived from the scenario, one file per service
    logs/<program>.log   each program's stdout and stderr

Modules: :mod:`.model` (the deployment file, pydantic), :mod:`.conf` (the run directory
and supervisord.conf), :mod:`.rpc` (supervisord's XML-RPC interface), :mod:`.wait`
(until programs run and services are on the bus), :mod:`.commands` (up, down, ctl),
:mod:`.secure` (mTLS and access control) and :mod:`.router` (``zenav router``).
"""
