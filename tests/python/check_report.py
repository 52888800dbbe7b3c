#!/usr/bin/env python3
"""report.html is one self-contained page: inline SVG plots (heat maps as embedded PNG), no scripts, no external resources;
report.json and report.md agree with it on the verdict."""
import json
import re
import sys

d = sys.argv[1]
html = open(f"{d}/report.html", encoding="utf-8").read()
report = json.load(open(f"{d}/report.json"))
md = open(f"{d}/report.md", encoding="utf-8").read()
assert html.count("<svg") >= 5, "expected inline SVG plots"
assert "<script" not in html.lower(), "scripts are not allowed"
# Embedded images (data: URIs, the heat maps' PNGs) are part of the page; anything else is not.
external = [m for m in re.findall(r'(?:src|href)\s*=\s*"([^"]*)"|url\(([^)]*)\)', html) if not (m[0] or m[1]).startswith("data:image/png;base64,")]
assert not external, f"external references: {external[:3]}"
links = [u for u in re.findall(r"https?://[^\"' )]+", html) if u != "http://www.w3.org/2000/svg"]
assert not links, f"network references: {links[:3]}"
status = report["summary"]["status"]
assert (status == "pass") == md.startswith("# hairlut validation: PASS")
assert len(report["checks"]) >= 8
print(f"report ok: {status}, {len(report['checks'])} checks, {html.count('<svg')} inline SVG plots, {len(html)} bytes")
