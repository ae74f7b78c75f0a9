"""GSPro Open Connect v1 over TCP (the wire as docs/service.md describes it), so launch-monitor connectors written
for GSPro (MLM2PRO, Garmin R10, Mevo+, Square, OpenFlight) send their shots to golfflight unchanged: `golfflight serve
--connect-port`.

`framing` cuts the byte stream into JSON objects, `replies` answers each one (through the same GSPro mapping as
`POST /v1/gspro`) and writes the player information, `limits` bounds what one connector may do, `server` holds the
connections, in bounded turns of the event loop so that no connector holds up HTTP.
"""
