#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""report.html in a real browser: makes two runs of the smoke scene with --video, rolls them up
with `sonomap report`, opens report.html in headless Chromium (Debian's chromium) over the
DevTools protocol and asserts that every image loaded (naturalWidth > 0), every audio and video
element loaded its metadata (readyState >= 1, duration > 0) and nothing was logged as an error.
Skips, saying why, only when chromium is not installed.

Usage: report_html_browser.py SONOMAP_EXE SOURCE_DIR WORK_DIR"""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

SKIP = "SONOMAP-TEST-SKIPPED"
SMALL_CAMERA = ["sensor.width=320", "sensor.height=240", "sensor.intrinsics.fx=262.5",
                "sensor.intrinsics.fy=262.5", "sensor.intrinsics.cx=159.5", "sensor.intrinsics.cy=119.5"]
# What the page's elements say once loaded: a list of {tag, src, ok, detail}.
PROBE = """JSON.stringify([
  ...Array.from(document.images).map(e => ({tag: 'img', src: e.getAttribute('src'),
      ok: e.complete && e.naturalWidth > 0, detail: 'naturalWidth ' + e.naturalWidth})),
  ...Array.from(document.querySelectorAll('audio, video')).map(e => ({tag: e.tagName.toLowerCase(),
      src: e.getAttribute('src'), ok: e.readyState >= 1 && e.duration > 0,
      detail: 'readyState ' + e.readyState + ', duration ' + e.duration +
              (e.error ? ', error ' + e.error.code + ' ' + e.error.message : '')}))])"""


def make_report(sonomap, source, work):
    report = os.path.join(work, "report")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(os.path.join(report, "runs"))
    sets = sum((["--set", s] for s in SMALL_CAMERA), [])
    # One sweep is enough for an audio player (the room's BRIRs take the most time).
    for mapper, sweeps in (("vdb_gpdf", []), ("tsdf", ["--sweeps", "-1"])):
        subprocess.run([sonomap, "--quiet", "run", os.path.join(source, "scenes", "smoke.yaml"),
                        "--out", os.path.join(report, "runs", mapper), "--frames", "6",
                        "--mapper", mapper, "--video", "--tag", "variant=" + mapper] + sweeps + sets,
                       check=True)
    subprocess.run([sonomap, "--quiet", "report", report], check=True)
    return os.path.join(report, "report.html")


class DevTools:
    """The few DevTools protocol calls the test needs, over one browser WebSocket (flat sessions)."""

    def __init__(self, url):
        import websocket  # Debian: python3-websocket
        # No Origin header: Chromium refuses DevTools connections from unlisted origins (403).
        self.ws = websocket.create_connection(url, timeout=30, suppress_origin=True)
        self.next_id = 0
        self.events = []

    def call(self, method, session=None, **params):
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params}
        if session:
            message["sessionId"] = session
        self.ws.send(json.dumps(message))
        while True:
            reply = json.loads(self.ws.recv())
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_for(self, method, seconds):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            if any(e.get("method") == method for e in self.events):
                return True
            self.ws.settimeout(max(0.1, deadline - time.monotonic()))
            self.events.append(json.loads(self.ws.recv()))
        return False


def errors_in(events):
    errors = []
    for e in events:
        method, p = e.get("method"), e.get("params", {})
        if method == "Runtime.exceptionThrown":
            errors.append("exception: " + json.dumps(p.get("exceptionDetails", {}))[:500])
        elif method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            errors.append("console." + p["type"] + ": " + json.dumps(p.get("args", []))[:500])
        elif method == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
            entry = p["entry"]
            errors.append(f"log ({entry.get('source')}): {entry.get('text')} {entry.get('url', '')}")
    return errors


def open_in_chromium(chromium, page):
    profile = tempfile.mkdtemp(prefix="sonomap-chromium-")
    browser = subprocess.Popen(
        [chromium, "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run",
         "--remote-debugging-port=0", "--remote-debugging-address=127.0.0.1", "--remote-allow-origins=*",
         "--user-data-dir=" + profile, "about:blank"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        url = None
        for line in browser.stderr:
            match = re.search(r"DevTools listening on (ws://\S+)", line)
            if match:
                url = match.group(1)
                break
        if not url:
            raise RuntimeError("chromium did not start its DevTools server")
        tools = DevTools(url)
        target = tools.call("Target.createTarget", url="about:blank")["targetId"]
        session = tools.call("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
        for domain in ("Runtime.enable", "Log.enable", "Page.enable"):
            tools.call(domain, session)
        tools.call("Page.navigate", session, url="file://" + os.path.abspath(page))
        if not tools.wait_for("Page.loadEventFired", 30):
            raise RuntimeError("the page did not finish loading in 30 s")
        deadline = time.monotonic() + 30  # media metadata may arrive after the load event
        while True:
            result = tools.call("Runtime.evaluate", session, expression=PROBE, returnByValue=True)
            elements = json.loads(result["result"]["value"])
            if all(e["ok"] for e in elements) or time.monotonic() > deadline:
                break
            time.sleep(0.2)
        return elements, errors_in(tools.events)
    finally:
        browser.kill()
        browser.wait()
        shutil.rmtree(profile, ignore_errors=True)


def main():
    sonomap, source, work = sys.argv[1:4]
    chromium = shutil.which("chromium")
    if not chromium:
        print(f"{SKIP}: chromium is not installed (ci/install-deps installs it)")
        return 0
    page = make_report(sonomap, source, work)
    elements, errors = open_in_chromium(chromium, page)
    failures = [f"{e['tag']} {e['src']} did not load: {e['detail']}" for e in elements if not e["ok"]]
    failures += errors
    counts = {tag: sum(e["tag"] == tag for e in elements) for tag in ("img", "audio", "video")}
    print(f"report.html: {counts['img']} images, {counts['audio']} audio players, "
          f"{counts['video']} videos")
    for tag, least in (("img", 2), ("audio", 1), ("video", 2)):  # two runs' pictures and videos, a sweep
        if counts[tag] < least:
            failures.append(f"expected at least {least} {tag} elements, found {counts[tag]}")
    for f in failures:
        print("FAIL:", f)
    if not failures:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
