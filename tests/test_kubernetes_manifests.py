"""deploy/kubernetes/: every manifest validates against the Kubernetes schemas (kubernetes-validate, strict, offline),
and the manifests agree with each other, with the serving image (Dockerfile) and with what `golfflight serve` does."""

from __future__ import annotations

import argparse
import copy
import re
from importlib.metadata import version
from pathlib import Path

import kubernetes_validate
import pytest
import yaml
from golfflight.service.api.guards import OPEN_PATHS
from golfflight.service.settings import API_KEY_ENV
from golfflight.service.api.routes.metrics import METRICS_PATH

from golfflight.commands import serve

ROOT = Path(__file__).resolve().parents[1]
MANIFESTS = ROOT / "deploy" / "kubernetes"
KUBERNETES_VERSION = "1.32.0"
"""The Kubernetes release whose schemas the manifests must meet (HPA autoscaling/v2 and every field used are GA)."""

SECRET_EXAMPLE = "secret.example.yaml"
"""Documents the Secret; never applied, so that no placeholder key reaches a cluster."""


def documents(name: str) -> list[dict]:
    return [doc for doc in yaml.safe_load_all((MANIFESTS / name).read_text()) if doc]


def manifest_files() -> list[str]:
    return sorted(path.name for path in MANIFESTS.glob("*.yaml") if path.name != "kustomization.yaml")


def resource(kind: str) -> dict:
    (found,) = [doc for name in manifest_files() for doc in documents(name) if doc["kind"] == kind]
    return found


@pytest.fixture(scope="module")
def deployment() -> dict:
    return resource("Deployment")


@pytest.fixture(scope="module")
def container(deployment) -> dict:
    (only,) = deployment["spec"]["template"]["spec"]["containers"]
    return only


@pytest.mark.parametrize("name", manifest_files())
def test_every_manifest_validates_against_the_kubernetes_schemas(name):
    for doc in documents(name):
        kubernetes_validate.validate(doc, KUBERNETES_VERSION, strict=True)  # raises on an unknown kind too


def test_the_validation_refuses_what_a_cluster_would(deployment):
    misspelt = copy.deepcopy(deployment)
    misspelt["spec"]["replica"] = misspelt["spec"].pop("replicas")
    with pytest.raises(kubernetes_validate.ValidationError, match="replica"):
        kubernetes_validate.validate(misspelt, KUBERNETES_VERSION, strict=True)
    wrong_type = copy.deepcopy(deployment)
    wrong_type["spec"]["template"]["spec"]["terminationGracePeriodSeconds"] = "45s"
    with pytest.raises(kubernetes_validate.ValidationError):
        kubernetes_validate.validate(wrong_type, KUBERNETES_VERSION, strict=True)


def test_the_kustomization_applies_every_manifest_but_the_secret_example_and_the_image_of_this_release(container):
    (kustomization,) = documents("kustomization.yaml")
    assert kustomization["kind"] == "Kustomization"
    assert sorted(kustomization["resources"]) == sorted(set(manifest_files()) - {SECRET_EXAMPLE})
    (image,) = kustomization["images"]
    assert image["name"] == container["image"] and image["newTag"] == version("golfflight")


def test_the_service_and_the_budget_select_the_deployments_pods(deployment, container):
    pod_labels = deployment["spec"]["template"]["metadata"]["labels"]
    selected = deployment["spec"]["selector"]["matchLabels"]
    assert selected.items() <= pod_labels.items()
    service = resource("Service")
    assert service["spec"]["selector"] == selected
    (port,) = service["spec"]["ports"]
    assert port["targetPort"] in {p["name"] for p in container["ports"]}
    assert resource("PodDisruptionBudget")["spec"]["selector"]["matchLabels"] == selected


def test_the_container_runs_serve_on_the_port_the_probes_and_the_image_use(container, deployment):
    parser = argparse.ArgumentParser()
    serve.register(parser.add_subparsers())
    args = parser.parse_args(container["args"])
    (port,) = container["ports"]
    assert args.host == "0.0.0.0" and args.port == port["containerPort"]
    dockerfile = (ROOT / "Dockerfile").read_text()
    assert re.search(rf"^EXPOSE {args.port}$", dockerfile, re.MULTILINE)
    for probe in ("startupProbe", "readinessProbe", "livenessProbe"):
        check = container[probe]["httpGet"]
        assert check["port"] == port["name"], probe
        assert check["path"] in OPEN_PATHS, f"{probe} on {check['path']} would need the API key"
    annotations = deployment["spec"]["template"]["metadata"]["annotations"]
    assert annotations["prometheus.io/port"] == str(args.port) and annotations["prometheus.io/path"] == METRICS_PATH


def test_the_pods_run_as_the_images_user_with_its_writable_paths_mounted(deployment, container):
    dockerfile = (ROOT / "Dockerfile").read_text()
    uid = re.search(r"useradd --create-home --uid (\d+) (\w+)", dockerfile)
    assert deployment["spec"]["template"]["spec"]["securityContext"]["runAsUser"] == int(uid[1])
    assert container["securityContext"]["readOnlyRootFilesystem"]
    mounted = {mount["mountPath"] for mount in container["volumeMounts"]}
    assert mounted == {"/tmp", f"/home/{uid[2]}/.cache"}


def test_the_api_key_comes_from_the_secret_the_example_describes(container):
    (variable,) = [env for env in container["env"] if env["name"] == API_KEY_ENV]
    reference = variable["valueFrom"]["secretKeyRef"]
    (secret,) = documents(SECRET_EXAMPLE)
    assert reference["name"] == secret["metadata"]["name"]
    assert reference["key"] in secret["stringData"]
    assert not reference.get("optional", False), "a pod listening on 0.0.0.0 must not start without a key"
    assert secret["stringData"][reference["key"]].startswith("REPLACE"), "only a placeholder belongs in the repo"


def test_the_autoscaler_scales_the_deployment_on_cpu_it_requests(deployment, container):
    hpa = resource("HorizontalPodAutoscaler")
    target = hpa["spec"]["scaleTargetRef"]
    assert (target["apiVersion"], target["kind"], target["name"]) == (
        deployment["apiVersion"],
        "Deployment",
        deployment["metadata"]["name"],
    )
    (metric,) = hpa["spec"]["metrics"]
    assert metric["resource"]["name"] == "cpu" and metric["resource"]["target"]["type"] == "Utilization"
    assert "cpu" in container["resources"]["requests"], "CPU utilisation is measured against the request"
    assert hpa["spec"]["minReplicas"] <= deployment["spec"]["replicas"] <= hpa["spec"]["maxReplicas"]


def mebibytes(quantity: str) -> float:
    number, unit = re.fullmatch(r"(\d+)(Mi|Gi)", quantity).groups()
    return int(number) * (1024 if unit == "Gi" else 1)


def test_requests_fit_within_limits(container):
    requests, limits = container["resources"]["requests"], container["resources"]["limits"]
    assert mebibytes(requests["memory"]) <= mebibytes(limits["memory"])
    assert float(requests["cpu"]) <= float(limits["cpu"])


def test_termination_waits_for_the_prestop_sleep_and_the_whole_drain(deployment, container):
    pod = deployment["spec"]["template"]["spec"]
    command = container["lifecycle"]["preStop"]["exec"]["command"]
    assert command[0] == "sleep"
    assert pod["terminationGracePeriodSeconds"] > int(command[1]) + serve.GRACEFUL_SHUTDOWN_S
