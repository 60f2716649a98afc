#!/usr/bin/env python3
"""Opens a forkbench report in headless Chromium (Debian's `chromium`) and checks it:
the page loads with no console errors, and every plot element is present with content.
Optionally saves a screenshot. Usage:
  tools/check_report.py DIR/report.html [--screenshot OUT.png] [--require heatmap]"""
import re
import subprocess
import sys
from html.parser import HTMLParser

args = sys.argv[1:]
page = args.pop(0)
shot = None
if "--screenshot" in args:
    i = args.index("--screenshot")
    shot = args[i + 1]
    del args[i : i + 2]
extra = []
while "--require" in args:
    i = args.index("--require")
    extra.append(args[i + 1])
    del args[i : i + 2]
url = "file://" + subprocess.check_output(["realpath", page], text=True).strip()
base = ["chromium", "--headless=new", "--no-sandbox", "--disable-gpu", "--hide-scrollbars"]
run = subprocess.run(
    base + ["--enable-logging=stderr", "--v=0", "--virtual-time-budget=5000", "--dump-dom", url],
    capture_output=True, text=True, timeout=120,
)
console = [l for l in run.stderr.splitlines() if "CONSOLE" in l]
errors = [l for l in console if re.search(r"error|uncaught|failed", l, re.I)]
if run.returncode != 0 or errors:
    sys.exit(f"{page}: chromium exit {run.returncode}, console errors: {errors or run.stderr[-2000:]}")


class Plots(HTMLParser):
    def __init__(self):
        super().__init__()
        self.plots, self.shapes, self.current = {}, {}, None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "svg" and "data-plot" in a:
            self.current = a["data-plot"]
            self.plots[self.current] = True
            self.shapes[self.current] = 0
        elif self.current and tag in ("rect", "path", "polyline", "circle", "line"):
            self.shapes[self.current] += 1

    def handle_endtag(self, tag):
        if tag == "svg":
            self.current = None


p = Plots()
p.feed(run.stdout)
required = ["failures", "errors-lateral", "errors-heading"] + extra
missing = [r for r in required if not any(k == r or k.startswith(r) for k in p.plots)]
empty = [k for k, n in p.shapes.items() if n == 0]
if missing or empty or "<table" not in run.stdout:
    sys.exit(f"{page}: missing plots {missing}, empty plots {empty}")
print(f"{page}: loads in Chromium without console errors; {len(p.plots)} plots: {', '.join(sorted(p.plots))}")
if shot:
    subprocess.run(base + ["--window-size=1300,2600", f"--screenshot={shot}", url], capture_output=True, timeout=120, check=True)
    print(f"screenshot: {shot}")
