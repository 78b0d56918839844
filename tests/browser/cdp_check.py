#!/usr/bin/env python3
"""Opens an attsync view.html in headless Chromium, offline, and checks it.

Drives Chromium through the DevTools protocol over --remote-debugging-pipe
(JSON messages separated by NUL: we write on the browser's fd 3 and read its
fd 4), Python's standard library only. Checks:
  - no request leaves the page: every Network.requestWillBeSent is the file
    itself (or a data: URL);
  - no console error, no uncaught exception, no Log error entry;
  - the 3D view at #t=T0&paused and at #t=T1&paused differs where the bodies
    are (pixels of the scene canvas, decoded from PNG screenshots), and the
    first is not blank;
  - the checker itself sees a blocked request: after the checks, the page is
    made to fetch http://127.0.0.1:9/, which its Content-Security-Policy must
    refuse with a console error (else the checks above prove nothing).
Prints a JSON report on stdout; exit 0 if every check passed, 1 if one
failed (reasons on stderr), 2 if Chromium is missing.

Usage: cdp_check.py VIEW_HTML [--times T0 T1] [--screenshot PNG --at T]
"""

import argparse
import base64
import fcntl
import json
import os
import pathlib
import queue
import struct
import sys
import tempfile
import threading
import time
import zlib

CHROMIUM = "/usr/bin/chromium"
FLAGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--disable-extensions", "--disable-default-apps", "--hide-scrollbars", "--mute-audio",
    "--remote-debugging-pipe",
]
WIDTH, HEIGHT = 1200, 760


class Browser:
    """A headless Chromium driven over its DevTools pipe."""

    def __init__(self, chromium, profile, log):
        to_r, to_w = os.pipe()
        from_r, from_w = os.pipe()
        # The browser reads fd 3 and writes fd 4: move our ends out of the way first.
        hi = [fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 10) for fd in (to_r, from_w)]
        for fd in (to_r, from_w):
            os.close(fd)
        args = [chromium, *FLAGS, "--user-data-dir=" + profile, "about:blank"]
        actions = [
            (os.POSIX_SPAWN_OPEN, 0, "/dev/null", os.O_RDONLY, 0),
            (os.POSIX_SPAWN_DUP2, log.fileno(), 1),
            (os.POSIX_SPAWN_DUP2, log.fileno(), 2),
            (os.POSIX_SPAWN_DUP2, hi[0], 3),
            (os.POSIX_SPAWN_DUP2, hi[1], 4),
        ]
        self.pid = os.posix_spawn(chromium, args, os.environ, file_actions=actions)
        for fd in hi:
            os.close(fd)
        self.out = os.fdopen(to_w, "wb", buffering=0)
        self.inp = os.fdopen(from_r, "rb", buffering=0)
        self.next_id = 0
        self.replies = {}
        self.events = queue.Queue()
        self.lock = threading.Condition()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        buf = b""
        while True:
            chunk = self.inp.read(65536)
            if not chunk:
                with self.lock:
                    self.replies["closed"] = True
                    self.lock.notify_all()
                return
            buf += chunk
            while b"\0" in buf:
                raw, buf = buf.split(b"\0", 1)
                msg = json.loads(raw)
                if "id" in msg:
                    with self.lock:
                        self.replies[msg["id"]] = msg
                        self.lock.notify_all()
                else:
                    self.events.put(msg)

    def call(self, method, params=None, session=None, timeout=20.0):
        self.next_id += 1
        n = self.next_id
        msg = {"id": n, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        self.out.write(json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + timeout
        with self.lock:
            while n not in self.replies:
                left = deadline - time.monotonic()
                if left <= 0 or "closed" in self.replies:
                    raise RuntimeError(f"no reply to {method} (browser gone or too slow)")
                self.lock.wait(left)
            reply = self.replies.pop(n)
        if "error" in reply:
            raise RuntimeError(f"{method}: {reply['error']}")
        return reply.get("result", {})

    def drain(self):
        out = []
        while True:
            try:
                out.append(self.events.get_nowait())
            except queue.Empty:
                return out

    def close(self):
        try:
            self.call("Browser.close", timeout=5)
        except RuntimeError:
            pass
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline:
            pid, _ = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                return
            time.sleep(0.05)
        os.kill(self.pid, 9)
        os.waitpid(self.pid, 0)


def evaluate(b, session, expr):
    r = b.call("Runtime.evaluate", {"expression": expr, "returnByValue": True}, session)
    return r.get("result", {}).get("value")


def wait_rendered(b, session, t, timeout=20.0):
    want = f"{t:.3f}"
    deadline = time.monotonic() + timeout
    got = None
    while time.monotonic() < deadline:
        got = evaluate(b, session, "document.documentElement.getAttribute('data-rendered')")
        if got == want:
            return
        time.sleep(0.02)
    raise RuntimeError(f"the page did not draw t = {want} (data-rendered = {got!r})")


def screenshot(b, session, clip=None):
    params = {"format": "png"}
    if clip:
        params["clip"] = clip
    return base64.b64decode(b.call("Page.captureScreenshot", params, session)["data"])


def decode_png(data):
    """RGBA rows of an 8-bit RGB/RGBA non-interlaced PNG (what Chromium writes)."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, w = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        pos += 12 + n
        if kind == b"IHDR":
            w, h, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 8 and color in (2, 6) and interlace == 0, (depth, color, interlace)
            bpp = 4 if color == 6 else 3
        elif kind == b"IDAT":
            idat += body
    raw = zlib.decompress(idat)
    stride = w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        unfilter(f, line, prev, bpp)
        rows.append(line if bpp == 4 else rgba(line))
        prev = line
    return w, h, rows


def unfilter(f, line, prev, bpp):
    n = len(line)
    if f == 1:
        for i in range(bpp, n):
            line[i] = (line[i] + line[i - bpp]) & 255
    elif f == 2:
        for i in range(n):
            line[i] = (line[i] + prev[i]) & 255
    elif f == 3:
        for i in range(n):
            left = line[i - bpp] if i >= bpp else 0
            line[i] = (line[i] + ((left + prev[i]) >> 1)) & 255
    elif f == 4:
        for i in range(n):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            p = a + b - c
            pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255


def rgba(line):
    out = bytearray()
    for i in range(0, len(line), 3):
        out += line[i:i + 3] + b"\xff"
    return out


def compare(png_a, png_b):
    """(pixels, pixels that differ, pixels of A unlike its corner, i.e. drawn)."""
    wa, ha, a = decode_png(png_a)
    wb, hb, b = decode_png(png_b)
    assert (wa, ha) == (wb, hb), "screenshots of different sizes"
    bg = a[0][0:3]
    differ = drawn = 0
    for ra, rb in zip(a, b):
        for i in range(0, len(ra), 4):
            if sum(abs(ra[i + c] - rb[i + c]) for c in range(3)) > 24:
                differ += 1
            if sum(abs(ra[i + c] - bg[c]) for c in range(3)) > 24:
                drawn += 1
    return wa * ha, differ, drawn


def problems_of(events, page_url):
    """Requests that leave the page, console errors, exceptions, error logs."""
    out = []
    for e in events:
        m, p = e.get("method"), e.get("params", {})
        if m == "Network.requestWillBeSent":
            url = p["request"]["url"].split("#")[0]
            if url != page_url and not url.startswith("data:"):
                out.append(f"request to {p['request']['url']}")
        elif m == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            text = " ".join(str(a.get("value", a.get("description", ""))) for a in p.get("args", []))
            out.append(f"console {p['type']}: {text}")
        elif m == "Runtime.exceptionThrown":
            d = p.get("exceptionDetails", {})
            out.append(f"exception: {d.get('exception', {}).get('description', d.get('text'))}")
        elif m == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
            out.append(f"log error: {p['entry'].get('text')} {p['entry'].get('url', '')}")
    return out


def check(browser, html, times, shot):
    page_url = pathlib.Path(html).resolve().as_uri()
    target = browser.call("Target.createTarget", {"url": "about:blank"})["targetId"]
    s = browser.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
    for domain in ("Network", "Runtime", "Log", "Page"):
        browser.call(domain + ".enable", {}, s)
    metrics = {"width": WIDTH, "height": HEIGHT, "deviceScaleFactor": 1, "mobile": False}
    browser.call("Emulation.setDeviceMetricsOverride", metrics, s)
    browser.call("Page.navigate", {"url": f"{page_url}#t={times[0]}&paused"}, s)
    wait_rendered(browser, s, times[0])
    rect = json.loads(evaluate(browser, s, "JSON.stringify(document.getElementById('scene').getBoundingClientRect())"))
    clip = {"x": rect["x"], "y": rect["y"], "width": rect["width"], "height": rect["height"], "scale": 0.5}
    first = screenshot(browser, s, clip)
    evaluate(browser, s, f"location.hash = '#t={times[1]}&paused'")
    wait_rendered(browser, s, times[1])
    second = screenshot(browser, s, clip)
    if shot:
        evaluate(browser, s, f"location.hash = '#t={shot[1]}&paused'")
        wait_rendered(browser, s, shot[1])
        page = {"x": 0, "y": 0, "width": WIDTH, "height": HEIGHT, "scale": 0.75}
        pathlib.Path(shot[0]).write_bytes(screenshot(browser, s, page))
    time.sleep(0.2)  # late events (a failed load, a late exception) still count
    events = browser.drain()
    probe = "fetch('http://127.0.0.1:9/').catch(() => 0); 0"
    evaluate(browser, s, probe)
    deadline, seen = time.monotonic() + 5, []
    while time.monotonic() < deadline and not seen:
        time.sleep(0.05)
        seen = problems_of(browser.drain(), page_url)
    pixels, differ, drawn = compare(first, second)
    return {
        "url": page_url,
        "times": times,
        "problems": problems_of(events, page_url),
        "requests": [e["params"]["request"]["url"] for e in events if e.get("method") == "Network.requestWillBeSent"],
        "probe_seen": seen,
        "scene_pixels": pixels,
        "changed_pixels": differ,
        "drawn_pixels": drawn,
    }


def verdict(r):
    failed = [f"the page: {p}" for p in r["problems"]]
    if not r["probe_seen"]:
        failed.append("the probe request to http://127.0.0.1:9/ went unnoticed: the checks cannot see a request or a CSP error")
    if r["drawn_pixels"] < r["scene_pixels"] // 50:
        failed.append(f"the 3D view at t = {r['times'][0]} is blank ({r['drawn_pixels']} of {r['scene_pixels']} pixels drawn)")
    if r["changed_pixels"] < r["scene_pixels"] // 200:
        failed.append(f"the 3D view at t = {r['times'][0]} and t = {r['times'][1]} is the same "
                      f"({r['changed_pixels']} of {r['scene_pixels']} pixels differ)")
    return failed


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("html")
    ap.add_argument("--times", nargs=2, type=float, default=[0.0, 20.0])
    ap.add_argument("--screenshot", help="also save a screenshot of the whole page here")
    ap.add_argument("--at", type=float, default=4.0, help="time of --screenshot, s")
    ap.add_argument("--chromium", default=CHROMIUM)
    a = ap.parse_args()
    if not os.access(a.chromium, os.X_OK):
        print(f"{a.chromium} is missing: run tools/test-deps.sh as root (it installs Debian's chromium)", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory(prefix="attsync-chromium-") as profile, \
            open(os.path.join(profile, "chromium.log"), "wb") as log:
        browser = Browser(a.chromium, os.path.join(profile, "profile"), log)
        try:
            report = check(browser, a.html, a.times, (a.screenshot, a.at) if a.screenshot else None)
        except (RuntimeError, AssertionError) as e:
            log.flush()
            tail = pathlib.Path(log.name).read_text(errors="replace")[-2000:]
            print(f"browser check could not run: {e}\n--- chromium's output\n{tail}", file=sys.stderr)
            return 1
        finally:
            browser.close()
    print(json.dumps(report))
    failed = verdict(report)
    for f in failed:
        print(f, file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
