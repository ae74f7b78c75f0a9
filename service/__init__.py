"""Serving: the runtime flight engine, model location, the batch child process, the HTTP app (`service.api`) and
GSPro Open Connect over TCP (`service.open_connect`), all over the shot contract (`contract`). The physics it serves is
the `flight` package's."""
