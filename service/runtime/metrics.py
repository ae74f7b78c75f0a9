"""Prometheus metrics of the running service (GET /metrics, `service.api.routes.metrics`), with prometheus-client.

Each app has its own `CollectorRegistry` (tests build several apps in one process). Under `golfflight serve
--workers N` every worker is a process of its own and a scrape reaches whichever worker accepts it, so the workers
share prometheus-client's multiprocess mode: each writes its samples to files in $PROMETHEUS_MULTIPROC_DIR and a
scrape sums every worker's files (`shared_across_workers`, used by `golfflight serve`). One process alone keeps them
in memory. Either way a scrape of a pod gives the whole pod's counts.

The same measurements feed /v1/latency's rolling windows (`BayRuntime.record_simulation`, the HTTP app's
`RequestMetrics`): the windows give exact percentiles of one worker's last 10,000, the histograms cumulative buckets
over every worker.
"""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

from prometheus_client import CollectorRegistry, Counter, Histogram
from prometheus_client.exposition import CONTENT_TYPE_LATEST, generate_latest
from prometheus_client.metrics_core import InfoMetricFamily, Metric
from prometheus_client.multiprocess import MultiProcessCollector
from golfflight.errors import InputError
from golfflight.flight.environment_variables import METRICS_DIR, environment, set_for_children

MULTIPROC_ENV = METRICS_DIR
"""prometheus-client's switch to multiprocess mode: the directory the worker processes write their samples to."""

CONTENT_TYPE = CONTENT_TYPE_LATEST
"""Media type of GET /metrics: the Prometheus text exposition format."""

SECONDS_BUCKETS = (0.00025, 0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0, 10.0, 30.0)
"""Histogram buckets for durations: a single shot simulates in about half a millisecond, a 10,000-shot batch in about
a second, a request waits at most the 30 s drain."""

BATCH_SHOTS_BUCKETS = (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000)
"""Histogram buckets for shots per batch, up to the 10,000 a batch may hold."""


def started(path: Path) -> bool:
    """Whether a worker's sample file has its header: prometheus-client creates it empty and sizes it an instant
    later, and cannot read it in between (a scrape as a worker starts was answered 500, tests/test_metrics.py)."""
    try:
        return path.stat().st_size > 0
    except OSError:  # removed since it was listed
        return False


class StartedWorkersCollector(MultiProcessCollector):
    """prometheus-client's sum over the worker processes' sample files, leaving out a file its worker has not yet
    sized (it holds no sample)."""

    def __init__(self, registry: CollectorRegistry, directory: Path) -> None:
        super().__init__(registry, str(directory))
        self.directory = directory

    def collect(self) -> Iterable[Metric]:
        return self.merge([str(path) for path in self.directory.glob("*.db") if started(path)], accumulate=True)


ModelLabels = Callable[[], dict[str, str] | None]
"""The loaded model's info labels (variant, sha256, version), or None while it loads or after it failed to."""


class ModelInfoCollector:
    """A collector of `golfflight_model_info{variant, sha256, version} 1` once the model is loaded. A collector read
    at scrape time, not an `Info` metric: prometheus-client's multiprocess mode has no `Info`, and every worker of a
    server loads the same verified bundle, so the scraped worker's labels are the pod's."""

    def __init__(self, labels: ModelLabels):
        self._labels = labels

    def collect(self) -> Iterator[InfoMetricFamily]:
        labels = self._labels()
        if labels is not None:
            yield InfoMetricFamily("golfflight_model", "The model bundle the service flies.", value=labels)


class ServiceMetrics:
    """The service's metrics, registered in a registry of the app's own; `exposition()` is the body of GET /metrics."""

    def __init__(self, model_labels: ModelLabels):
        self.registry = CollectorRegistry()
        self.requests = Counter(
            "golfflight_http_requests",
            "HTTP requests answered, by route template, method and status (errors are status >= 400).",
            ["route", "method", "status"],
            registry=self.registry,
        )
        self.request_seconds = Histogram(
            "golfflight_http_request_duration_seconds",
            "Whole HTTP requests, receipt to last byte sent, by route template and method.",
            ["route", "method"],
            buckets=SECONDS_BUCKETS,
            registry=self.registry,
        )
        self.simulation_seconds = Histogram(
            "golfflight_simulation_duration_seconds",
            "Engine compute per simulation: kind=shot is one shot (HTTP, GSPro over HTTP or TCP), kind=batch a batch.",
            ["kind"],
            buckets=SECONDS_BUCKETS,
            registry=self.registry,
        )
        self.batch_shots = Histogram(
            "golfflight_batch_shots",
            "Shots per batch flown by POST /v1/shots/batch.",
            buckets=BATCH_SHOTS_BUCKETS,
            registry=self.registry,
        )
        self.registry.register(ModelInfoCollector(model_labels))
        self._scraped = self.registry
        if environment().metrics_dir:
            self._scraped = CollectorRegistry()
            StartedWorkersCollector(self._scraped, Path(environment().metrics_dir))
            self._scraped.register(ModelInfoCollector(model_labels))

    def exposition(self) -> bytes:
        """Every metric in the Prometheus text format: this process's, or every worker's in multiprocess mode."""
        return generate_latest(self._scraped)


@contextmanager
def shared_across_workers(workers: int) -> Iterator[Path | None]:
    """Multiprocess mode for a server's worker processes, set up before they start (they inherit the environment).

    With $PROMETHEUS_MULTIPROC_DIR set, that directory is used and the sample files an earlier run left in it are
    removed (they would be added to this run's counts). Otherwise several workers get a fresh temporary directory,
    removed when the server stops, and one worker keeps its metrics in memory (None)."""
    directory = environment().metrics_dir
    if directory:
        if not directory.is_dir():
            raise InputError(f"${MULTIPROC_ENV} is {str(directory)!r}: no such directory")
        for stale in directory.glob("*.db"):
            stale.unlink()
        yield directory
        return
    if workers == 1:
        yield None
        return
    directory = Path(tempfile.mkdtemp(prefix="golfflight-metrics-"))
    set_for_children(MULTIPROC_ENV, str(directory))
    try:
        yield directory
    finally:
        set_for_children(MULTIPROC_ENV, None)
        shutil.rmtree(directory, ignore_errors=True)
