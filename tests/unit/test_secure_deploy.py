"""The secured deployment files: per-party TLS transports and the router's policy."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
import yaml

from zenav.deploy.conf import prepare
from zenav.deploy.model import load_deployment
from zenav.deploy.secure import PARTIES, access_control
from zenav.services.config import ConfigError

REPO = Path(__file__).resolve().parents[2]


def test_policy_is_default_deny_and_only_the_planner_puts_commands() -> None:
    acl = access_control("robot0")
    assert acl["enabled"] and acl["default_permission"] == "deny"
    assert {s["id"] for s in acl["subjects"]} == set(PARTIES)
    assert all(s["cert_common_names"] == [s["id"]] for s in acl["subjects"])
    rules = {r["id"]: r for r in acl["rules"]}
    assert all(r["permission"] == "allow" for r in rules.values())

    def allowed(subject: str, message: str, flow: str, key: str) -> bool:
        policy_rules = [r for p in acl["policies"] if subject in p["subjects"]
                        for r in p["rules"]]
        return any(message in rules[r]["messages"] and flow in rules[r]["flows"]
                   and key in rules[r]["key_exprs"] for r in policy_rules)

    cmd = "zenav/robot0/cmd_vel"
    assert [s for s in PARTIES if allowed(s, "put", "ingress", cmd)] == ["planner"]
    assert [s for s in PARTIES if allowed(s, "put", "egress", cmd)] == ["motor_bridge"]
    assert [s for s in PARTIES if allowed(s, "declare_subscriber", "ingress", cmd)] == [
        "motor_bridge"]
    monitor_rules = [r for p in acl["policies"] if "monitor" in p["subjects"]
                     for r in p["rules"]]
    assert not any(rules[r]["flows"] == ["ingress"] and {"put", "query", "delete"}
                   & set(rules[r]["messages"]) for r in monitor_rules)


def test_secured_deployment_writes_one_transport_per_party(tmp_path: Path) -> None:
    certs = tmp_path / "certs"
    subprocess.run(["sh", str(REPO / "deploy" / "secure" / "make-certs.sh"), str(certs)],
                   check=True, capture_output=True)
    data = yaml.safe_load((REPO / "deploy" / "secure" / "robot.yaml").read_text())
    data["security"]["certs"] = str(certs)
    data["scenario"] = str(REPO / "sim" / "scenarios" / "a-no-obstacle.yaml")
    for spec in data["services"].values():
        spec["config"] = [str((REPO / "deploy" / "secure" / p).resolve())
                          for p in spec["config"]]
    path = tmp_path / "robot.yaml"
    path.write_text(yaml.safe_dump(data))
    run_dir = tmp_path / "run"
    prepare(load_deployment(path), run_dir)
    router = yaml.safe_load((run_dir / "transport-router.yaml").read_text())
    assert router["mode"] == "router" and router["listen"] == ["tls/0.0.0.0:7447"]
    assert router["extra"]["access_control"]["default_permission"] == "deny"
    assert router["extra"]["transport/link/tls/enable_mtls"] is True
    bridge = yaml.safe_load((run_dir / "transport-motor_bridge.yaml").read_text())
    assert bridge["extra"]["transport/link/tls/connect_certificate"].endswith(
        "motor_bridge.pem")
    conf = (run_dir / "supervisord.conf").read_text()
    assert "transport-router.yaml" in conf and "transport-simulator.yaml" in conf
    (certs / "planner.pem").unlink()
    with pytest.raises(ConfigError, match=r"security.certs: .* lacks planner.pem"):
        load_deployment(path)
