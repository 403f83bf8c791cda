"""A secured deployment: mutual TLS on every link and access control on the router.

Every party has a certificate from the deployment's own authority (made by
``deploy/secure/make-certs.sh``) whose common name is its name: ``router``, the six
services, ``monitor`` and ``run``. The robot's router accepts only TLS connections from
certificates of that authority (mutual TLS) and applies the access control below, with
the certificates' common names as subjects. Everything not allowed is denied:

- each service may put only on its own outputs and its ``status/<service>`` key, and
  receive only its own inputs; in particular only the planner may put on ``cmd_vel`` and
  only the motor bridge may subscribe to it;
- a ``monitor`` may only subscribe: every key of the robot but ``cmd_vel``, and the
  liveliness tokens; it may put nothing, query nothing and hold no token;
- ``run`` (the driver of ``zenav run`` or a test) holds its token, reads the run's
  result, events and odometry, and queries the planner's history.

A denied put is dropped silently by Zenoh: test it on the receiver.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from zenav.schemas import keys
from zenav.schemas.keys import Keys

SERVICE_IO: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    # service: (inputs, outputs), as topic names
    "simulator": ((keys.BASE_CMD.name,), (keys.RAW_LASER.name, keys.ODOM.name,
                                          keys.TRUTH.name, keys.RESULT.name)),
    "laser_driver": ((keys.RAW_LASER.name,), (keys.SCAN.name,)),
    "perception": ((keys.SCAN.name, keys.ODOM.name), (keys.OBSTACLES.name,)),
    "tracking": ((keys.OBSTACLES.name,), (keys.TRACKS.name,)),
    "planner": ((keys.TRACKS.name,), (keys.CMD_VEL.name, keys.EVENTS.name,
                                      keys.PLANNER_STATE.name)),
    "motor_bridge": ((keys.SCAN.name, keys.CMD_VEL.name, keys.ODOM.name),
                     (keys.BASE_CMD.name,)),
}
"""What each service reads and writes (as in deploy/graph.yaml)."""

RUN_INPUTS = (keys.RESULT.name, keys.EVENTS.name, keys.ODOM.name)
PARTIES = (*SERVICE_IO, "monitor", "run")
"""Every common name the access control knows (plus ``router``, the router's own)."""


def _rule(rule_id: str, messages: list[str], flows: list[str], key_exprs: list[str]) -> dict[
        str, Any]:
    return {"id": rule_id, "permission": "allow", "messages": messages, "flows": flows,
            "key_exprs": key_exprs}


def access_control(robot_id: str) -> dict[str, Any]:
    """The router's ``access_control`` section: default deny, subjects by common name."""
    k = Keys(robot_id)
    every_topic = [t.name for t in keys.TOPICS]
    readable = [f"{k.prefix}/{n}" for n in every_topic if n != keys.CMD_VEL.name]
    readable.append(k.status_any)
    rules: list[dict[str, Any]] = []
    policies: list[dict[str, Any]] = []

    def grant(subject: str, *rule_list: dict[str, Any]) -> None:
        rules.extend(rule_list)
        policies.append({"id": f"{subject}-policy", "rules": [r["id"] for r in rule_list],
                         "subjects": [subject]})

    # Declarations flowing out carry no data: every party may learn who subscribes,
    # answers or is alive, so that publishers send and liveliness works.
    common = [
        _rule("learn-declarations", ["declare_subscriber", "declare_queryable",
                                     "liveliness_token"], ["egress"], [k.everything]),
        _rule("watch-liveliness", ["declare_liveliness_subscriber", "liveliness_query"],
              ["ingress"], [f"{k.prefix}/alive/**"]),
        _rule("see-liveliness", ["liveliness_token"], ["egress"], [f"{k.prefix}/alive/**"]),
    ]
    rules.extend(common)
    policies.append({"id": "everyone", "rules": [r["id"] for r in common],
                     "subjects": list(PARTIES)})
    for service, (inputs, outputs) in SERVICE_IO.items():
        ins = [f"{k.prefix}/{n}" for n in inputs]
        outs = [f"{k.prefix}/{n}" for n in outputs] + [k.status(service)]
        own = [
            _rule(f"{service}-put", ["put"], ["ingress"], outs),
            _rule(f"{service}-token", ["liveliness_token"], ["ingress"], [k.alive(service)]),
            _rule(f"{service}-subscribe", ["declare_subscriber"], ["ingress"], ins),
            _rule(f"{service}-receive", ["put"], ["egress"], ins),
        ]
        if service == "planner":
            history = [k.of(keys.EVENT_HISTORY)]
            own += [_rule("planner-answer", ["declare_queryable", "reply"], ["ingress"], history),
                    _rule("planner-asked", ["query"], ["egress"], history)]
        grant(service, *own)
    grant("monitor",
          _rule("monitor-subscribe", ["declare_subscriber"], ["ingress"], [k.everything]),
          _rule("monitor-receive", ["put"], ["egress"], readable))
    runs = [f"{k.prefix}/{n}" for n in RUN_INPUTS]
    grant("run",
          _rule("run-token", ["liveliness_token"], ["ingress"], [k.alive("run")]),
          _rule("run-subscribe", ["declare_subscriber"], ["ingress"], runs),
          _rule("run-receive", ["put"], ["egress"], runs),
          _rule("run-ask", ["query"], ["ingress"], [k.of(keys.EVENT_HISTORY)]),
          _rule("run-answered", ["reply"], ["egress"], [k.of(keys.EVENT_HISTORY)]))
    subjects = [{"id": name, "cert_common_names": [name]} for name in PARTIES]
    return {"enabled": True, "default_permission": "deny", "rules": rules,
            "subjects": subjects, "policies": policies}


def tls_settings(cert_dir: Path, name: str, *, listen: bool) -> dict[str, Any]:
    """Zenoh settings (path -> value) for ``name``'s TLS link with mutual
    authentication: its certificate and key, and the deployment's authority."""
    d = cert_dir.resolve()
    role = "listen" if listen else "connect"
    settings: dict[str, Any] = {
        "transport/link/tls/root_ca_certificate": str(d / "ca.pem"),
        "transport/link/tls/enable_mtls": True,
        f"transport/link/tls/{role}_certificate": str(d / f"{name}.pem"),
        f"transport/link/tls/{role}_private_key": str(d / f"{name}.key"),
    }
    return settings
