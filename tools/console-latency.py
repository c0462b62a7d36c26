#!/usr/bin/env python3
"""The console's page update latency (issue 70): from a blackout asked over the API to the pushed state
(GET /api/events) saying so, as a page sees it. Start `projbot run --sim --headless --console PORT` first.

    python3 tools/console-latency.py PORT [TIMES]

Prints p50, p95 and max over TIMES toggles (default 20). Standard library only."""
import http.client
import json
import sys
import threading
import time


def main():
    port = int(sys.argv[1])
    times = int(sys.argv[2]) if len(sys.argv) > 2 else 20
    seen = []  # (time, blackout) of each event
    done = threading.Event()

    def listen():
        c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
        c.request("GET", "/api/events")
        r = c.getresponse()
        while not done.is_set():
            line = r.fp.readline()
            if not line:
                break
            if line.startswith(b"data: "):
                seen.append((time.monotonic(), json.loads(line[6:])["blackout"]))

    threading.Thread(target=listen, daemon=True).start()
    time.sleep(1.0)
    latencies = []
    for k in range(times):
        want = k % 2 == 0
        c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
        t0 = time.monotonic()
        c.request("POST", "/api/blackout", json.dumps({"on": want}), {"Content-Type": "application/json"})
        if c.getresponse().status != 200:
            sys.exit("the console refused the blackout")
        while time.monotonic() - t0 < 5.0:
            hit = [t for t, b in list(seen) if t >= t0 and b == want]
            if hit:
                latencies.append(1000.0 * (hit[0] - t0))
                break
            time.sleep(0.002)
        time.sleep(0.3)
    done.set()
    latencies.sort()
    if not latencies:
        sys.exit("no state change was pushed")
    pick = lambda q: latencies[min(len(latencies) - 1, int(q * len(latencies)))]
    print(f"page update latency over {len(latencies)} blackout toggles: p50 {pick(0.5):.0f} ms, "
          f"p95 {pick(0.95):.0f} ms, max {latencies[-1]:.0f} ms")


if __name__ == "__main__":
    main()
