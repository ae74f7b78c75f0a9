"""Evaluation and reports of flight models: accuracy on the real sets, physics checks, held-out results, noise floors
and figures. Torch-free: every model here is flown through the runtime path (`flight`), so a runtime install can
evaluate; training (`model_export`) may import this package, never the reverse."""
