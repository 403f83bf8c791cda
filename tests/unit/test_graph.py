"""deploy/graph.yaml against the services themselves, and the graph's consistency: every
key a service reads has exactly one message type among its writers, the expected one."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from typing import Any

import pytest
import yaml

from zenav.graph import derive_graph, probe_service, schema_digest
from zenav.schemas import keys
from zenav.schemas.keys import Topic
from zenav.schemas.messages import ALL_MESSAGES
from zenav.services.runner import PLANNERS

GRAPH = Path(__file__).resolve().parents[2] / "deploy" / "graph.yaml"
MESSAGES = {m.__name__: m for m in ALL_MESSAGES}


@pytest.fixture(scope="module")
def documented() -> dict[str, Any]:
    data: dict[str, Any] = yaml.safe_load(GRAPH.read_text())
    return data


@pytest.fixture(scope="module")
def derived() -> dict[str, Any]:
    return derive_graph()


def test_graph_yaml_lists_what_the_services_declare(documented, derived):
    assert documented["services"].keys() == derived["services"].keys()
    for service, entry in derived["services"].items():
        assert documented["services"][service] == entry, (
            f"deploy/graph.yaml is out of date for {service}; `zenav graph` prints the code's")
    assert documented == derived  # keys, schema version, every-service part, messages


def test_every_subscribed_key_has_exactly_one_publisher_type_and_it_matches(documented):
    writers: dict[str, set[str]] = defaultdict(set)
    for entry in documented["services"].values():
        for topic, message in entry["publishes"].items():
            writers[topic].add(message)
    for service, entry in documented["services"].items():
        for topic, message in entry["subscribes"].items():
            assert writers[topic], f"{service} reads {topic}, which nothing publishes"
            assert writers[topic] == {message}, (
                f"{service} reads {topic} as {message}; publishers send {writers[topic]}")
            schema = documented["messages"][message]["schema"]
            assert schema == schema_digest(MESSAGES[message])


def test_the_graph_agrees_with_the_key_registry_and_the_schemas(documented):
    registry = {t.name: t.message.__name__ for t in vars(keys).values() if isinstance(t, Topic)}
    for entry in documented["services"].values():
        for topic, message in {**entry["subscribes"], **entry["publishes"],
                               **entry.get("answers", {})}.items():
            assert registry[topic] == message
    for name, info in documented["messages"].items():
        assert info["wire"] == MESSAGES[name].TYPE
        assert info["schema"] == schema_digest(MESSAGES[name])


@pytest.mark.parametrize("planner", sorted(PLANNERS))
def test_every_planner_implementation_can_replace_the_planner(documented, planner):
    """Whatever it reads is in the graph with that type; what it writes is the planner's."""
    entry, _ = probe_service("planner", planner)
    writers = {topic: message for service, e in documented["services"].items()
               if service != "planner" for topic, message in e["publishes"].items()}
    for topic, message in entry["subscribes"].items():
        assert writers.get(topic) == message, f"{planner} reads {topic} as {message}"
    expected = documented["services"]["planner"]["publishes"]
    assert set(entry["publishes"].items()) <= set(expected.items())
    assert entry["publishes"]["cmd_vel"] == "VelocityCommand"


def test_a_schema_change_shows_in_the_digest():
    from zenav.schemas.messages import Odometry, VelocityCommand

    assert schema_digest(Odometry) != schema_digest(VelocityCommand)
    assert len(schema_digest(Odometry)) == 16
