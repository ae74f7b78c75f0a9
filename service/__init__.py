"""Serving: the runtime flight engine, model location, trajectory resampling, the HTTP app (`service.api`) and GSPro
Open Connect over TCP (`service.open_connect`). The physics it serves is the `flight` package's."""
