"""The bay runtime (`BayRuntime`): the engine, the bay's conditions and player, the batch process, the metrics and
the shot feed, below its adapters (HTTP `service.api`, GSPro Open Connect `service.open_connect`, the viewer
`service.viewer`), none of which imports another."""

from golfflight.service.runtime.runtime import BayRuntime, Flown, NotReady, runtime_of

__all__ = ["BayRuntime", "Flown", "NotReady", "runtime_of"]
