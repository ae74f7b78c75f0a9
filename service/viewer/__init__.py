"""The live shot viewer, an adapter on the bay runtime: every shot the bay's screens are sent (the runtime's feed,
`service.runtime.feed`) is rendered once as a `ShotEvent` (`frames`, `event`) with the states of the flight that
was answered, streamed to browsers as server-sent events (`stream`) and drawn by a page shipped in `static/` (no CDN:
simulator bays are often offline). Its routes (`routes`) also give the session's shots as CSV."""
