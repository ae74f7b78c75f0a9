"""The live shot viewer: every shot the service flies (HTTP single and batch, GSPro over HTTP and TCP) is kept in a
bounded feed (`feed`), streamed to browsers as server-sent events (`ShotEvent`, `event`) and drawn by a page shipped
in `static/` (no CDN: simulator bays are often offline). The routes are in `service.api.routes.viewer`."""
