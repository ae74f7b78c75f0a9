"""Holds sockets to an Open Connect port, sending nothing, each connecting again as soon as it is closed (it reads
only to see the close): a flood of sockets that never send a valid message, as a hostile program's loop makes one.

python benchmarks/silent_flood.py PORT [COUNT] [SOURCE]   (COUNT sockets, 20 by default, from address SOURCE,
                                                        127.0.0.1 by default; prints "connected" once all are)

Used by bench_places.py and tests/test_open_connect_waiting.py, in a process of its own; runs until killed.
"""

import select
import socket
import sys


def opened(port: int, source: str) -> socket.socket:
    """A new connection to the port on loopback, from address `source`."""
    return socket.create_connection(("127.0.0.1", port), source_address=(source, 0))


def main() -> None:
    """Connect COUNT sockets, say so, then replace each one the server closes, until killed."""
    port, count = int(sys.argv[1]), int(sys.argv[2]) if len(sys.argv) > 2 else 20
    source = sys.argv[3] if len(sys.argv) > 3 else "127.0.0.1"
    sockets = [opened(port, source) for _ in range(count)]
    print("connected", flush=True)
    while True:
        for sock in select.select(sockets, [], [], 0.05)[0]:
            try:
                data = sock.recv(65536)
            except OSError:
                data = b""
            if not data:
                sock.close()
                sockets[sockets.index(sock)] = opened(port, source)


if __name__ == "__main__":
    main()
