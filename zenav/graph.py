"""The service graph: each service's input and output keys with their message types,
taken from the services themselves.

Each service is built on the in-memory bus with a probing node that notes every
``publisher`` and ``subscribe`` call and every liveliness watch; nothing runs. The result
is what ``deploy/graph.yaml`` documents (a test keeps the two equal) and what a
replacement process must speak: the same keys, the same message types (the schema
digest identifies a message's JSON Schema), and a liveliness token ``alive/<service>``.
"""

from __future__ import annotations

import argparse
import hashlib
import json
from typing import Any

import yaml

from zenav.schemas import keys
from zenav.schemas.codec import SCHEMA_VERSION
from zenav.schemas.keys import Keys, Topic
from zenav.schemas.messages import ALL_MESSAGES, Message
from zenav.services.config import SERVICE_ORDER
from zenav.services.node import Handler, M, Node, TypedPublisher
from zenav.services.transport import InMemoryBus, LivelinessCallback, Snapshot, Subscription
from zenav.sim import SCENARIO_DIR

PROBE_ROBOT = "graph"

KNOWN_TOPICS: dict[str, type[Message]] = {
    t.name: t.message for t in vars(keys).values() if isinstance(t, Topic)}
"""Every topic schemas/keys.py defines, with its message type."""

SCENARIO = SCENARIO_DIR / "a-no-obstacle.yaml"
"""The simulator needs a scenario to be built; any will do."""


def schema_digest(message: type[Message]) -> str:
    """First 16 hex digits of the SHA-256 of the message's JSON Schema (sorted keys)."""
    schema = json.dumps(message.model_json_schema(mode="serialization"), sort_keys=True)
    return hashlib.sha256(schema.encode()).hexdigest()[:16]


class _ProbeBus(InMemoryBus):
    def __init__(self) -> None:
        super().__init__()
        self.watched: list[str] = []
        self.answered: list[str] = []

    def declare_queryable(self, key: str, snapshot: Snapshot) -> None:
        self.answered.append(key)
        super().declare_queryable(key, snapshot)

    def watch_liveliness(self, key_expr: str, callback: LivelinessCallback) -> None:
        self.watched.append(key_expr)
        super().watch_liveliness(key_expr, callback)


class _ProbeNode(Node):
    def __init__(self, name: str, bus: _ProbeBus, keys_: Keys) -> None:
        super().__init__(name, bus, keys_)
        self.inputs: dict[str, type[Message]] = {}
        self.outputs: dict[str, type[Message]] = {}

    def publisher(self, topic: Topic, message_type: type[M], *, reliable: bool = False,
                  urgent: bool = False) -> TypedPublisher[M]:
        self.outputs[topic.name] = message_type
        return super().publisher(topic, message_type, reliable=reliable, urgent=urgent)

    def subscribe(self, topic: Topic, message_type: type[M], handler: Handler[M], *,
                  depth: int = 1) -> Subscription:
        self.inputs[topic.name] = message_type
        return super().subscribe(topic, message_type, handler, depth=depth)


def _relative(key_expr: str, k: Keys) -> str:
    return key_expr.removeprefix(k.prefix + "/")


def probe_service(name: str, planner: str = "paper") -> tuple[dict[str, Any], set[type[Message]]]:
    """One service's graph entry, and the message types it uses, from its code."""
    from zenav.services.runner import implementation

    k = Keys(PROBE_ROBOT)
    module = implementation(name, planner)
    params = module.Params(scenario=SCENARIO) if name == "simulator" else module.Params()
    bus = _ProbeBus()
    node = _ProbeNode(name, bus, k)
    module.Service(node, params)
    entry: dict[str, Any] = {
        "subscribes": {t: m.__name__ for t, m in sorted(node.inputs.items())},
        "publishes": {t: m.__name__ for t, m in sorted(node.outputs.items())},
    }
    used = set(node.inputs.values()) | set(node.outputs.values())
    if bus.answered:  # queryables: a late joiner fetches history (zenav run does)
        answers = {_relative(a, k): KNOWN_TOPICS[_relative(a, k)] for a in bus.answered}
        entry["answers"] = {t: m.__name__ for t, m in sorted(answers.items())}
        used.update(answers.values())
    if bus.watched:
        entry["watches"] = sorted(_relative(w, k) for w in bus.watched)
    return entry, used


def derive_graph() -> dict[str, Any]:
    """The graph as deploy/graph.yaml writes it, from the code (the paper's planner)."""
    services: dict[str, Any] = {}
    used: set[type[Message]] = {keys.STATUS.message}
    for name in SERVICE_ORDER:
        services[name], types = probe_service(name)
        used |= types
    messages = {
        m.__name__: {"wire": m.TYPE, "schema": schema_digest(m)}
        for m in ALL_MESSAGES if m in used
    }
    return {
        "keys": "zenav/<robot_id>/<topic>",
        "schema_version": SCHEMA_VERSION,
        "every_service": {
            "publishes": {keys.STATUS.name + "/<service>": keys.STATUS.message.__name__},
            "token": "alive/<service>",
        },
        "services": services,
        "messages": messages,
    }


def main(args: argparse.Namespace) -> int:
    print(yaml.safe_dump(derive_graph(), sort_keys=False, default_flow_style=None), end="")
    return 0


def add_command(sub: Any) -> None:
    graph = sub.add_parser("graph", help="print each service's input and output keys with "
                           "their message types (as in deploy/graph.yaml)")
    graph.set_defaults(func=main)
