#!/usr/bin/env python3
"""report.html of the default tables: its size, and its layout as a browser draws it.

    check_report_layout.py size   REPORT WORK   # report.html under 3 MB, heat maps as PNG
    check_report_layout.py layout REPORT WORK   # headless chromium: nothing clipped

REPORT is a directory validate-hair-luts wrote (ctest: the default tables' report, from the test
that validates them).

size: the report (REPORT/report.html) must be under 3 MB, embed its heat maps as PNG
images, give every heat-map axis a unit (angles in degrees, as the text) and label no colour bar
with a fractional power of ten (such as 1e-1.72).

layout: the page is loaded in headless chromium (Debian's chromium, an optional test dependency;
without it the test is skipped, exit 77, saying so) 1280 px wide, with a script that measures every
element: each must lie within the body (1200 px at most), and each SVG text within its SVG, where
anything outside is clipped. Then the whole page is screenshotted (WORK/report.png) at its full
height. Exit 1 lists what is clipped.
"""

import base64
import json
import re
import struct
import zlib
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

LIMIT_BYTES = 3 * 1024 * 1024

MEASURE = r"""
<script>
window.addEventListener('load', () => {
  const problems = [];
  const body = document.body.getBoundingClientRect();
  const say = (el) => `<${el.tagName.toLowerCase()}> "${(el.textContent || '').trim().replace(/\s+/g, ' ').slice(0, 50)}"`;
  for (const el of document.querySelectorAll('body *')) {
    if (el.tagName.toLowerCase() === 'script' || (el.closest('svg') && el.tagName.toLowerCase() !== 'svg')) continue;
    const r = el.getBoundingClientRect();
    if (r.width === 0 && r.height === 0) continue;
    if (r.right > body.right + 0.5 || r.left < body.left - 0.5)
      problems.push(`${say(el)} spans x ${r.left.toFixed(0)} to ${r.right.toFixed(0)}, beyond the body (${body.left.toFixed(0)} to ${body.right.toFixed(0)})`);
  }
  for (const svg of document.querySelectorAll('svg')) {
    const s = svg.getBoundingClientRect();
    for (const t of svg.querySelectorAll('text')) {
      const r = t.getBoundingClientRect();
      if (r.width === 0) continue;
      if (r.left < s.left - 0.5 || r.right > s.right + 0.5 || r.top < s.top - 0.5 || r.bottom > s.bottom + 0.5)
        problems.push(`${say(t)} in the SVG "${(svg.querySelector('text') || {}).textContent || ''}" is clipped (text ${r.left.toFixed(0)}..${r.right.toFixed(0)} x ${r.top.toFixed(0)}..${r.bottom.toFixed(0)}, SVG ${s.left.toFixed(0)}..${s.right.toFixed(0)} x ${s.top.toFixed(0)}..${s.bottom.toFixed(0)})`);
    }
  }
  const out = document.createElement('pre');
  out.id = 'layout-result';
  out.textContent = JSON.stringify({problems, width: document.documentElement.scrollWidth, height: document.documentElement.scrollHeight,
                                    svgs: document.querySelectorAll('svg').length});
  document.body.appendChild(out);
});
</script>
"""


def png_problems(data):
    """A PNG decoded independently of the writer (zlib here, CRCs checked): 8-bit RGB, every row."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return ["an embedded image is not a PNG"]
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,), kind = struct.unpack(">I", data[pos:pos + 4]), data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])[0] != zlib.crc32(kind + body):
            return [f"an embedded PNG's {kind.decode()} chunk has a bad CRC"]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    if not header or header[2:5] != (8, 2, 0):
        return ["an embedded PNG is not 8-bit RGB"]
    raw = zlib.decompress(idat)
    if len(raw) != (header[0] * 3 + 1) * header[1]:
        return [f"an embedded PNG of {header[0]} x {header[1]} holds {len(raw)} bytes of rows"]
    return []


def check_size(html_path):
    html = html_path.read_text()
    size = html_path.stat().st_size
    problems = []
    if size >= LIMIT_BYTES:
        problems.append(f"report.html is {size / 1e6:.2f} MB, not under {LIMIT_BYTES / 1e6:.2f} MB")
    heat = html.count('class="heat-map"')
    pngs = html.count('href="data:image/png;base64,')
    rects = html.count("<rect")
    if heat and pngs < heat:
        problems.append(f"{heat} heat maps but {pngs} embedded PNG images")
    for bad in re.findall(r">1e-?\d+\.\d+<", html):
        problems.append(f"a colour-bar label with a fractional exponent: {bad[1:-1]}")
    for uri in re.findall(r'href="data:image/png;base64,([A-Za-z0-9+/=]+)"', html)[:50]:
        problems += png_problems(base64.b64decode(uri))
    for axis in re.findall(r">((?:theta_[a-z]|phi|beta|sigma_a)(?: \[[^\]]*\])?)</text>", html):
        if "[" not in axis:
            problems.append(f"an axis without a unit: {axis}")
        elif re.match(r"(theta|phi|beta)", axis) and "[deg]" not in axis:
            problems.append(f"an angle axis not in degrees: {axis}")
    print(f"report.html: {size} bytes ({size / 1e6:.2f} MB), {heat} heat maps, {pngs} PNG images, {rects} SVG rects")
    return problems


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def run_chromium(browser, args, profile):
    base = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking",
            "--disable-component-update", "--disable-sync", "--hide-scrollbars", f"--user-data-dir={profile}"]
    return subprocess.run(base + args, capture_output=True, text=True, timeout=300)


def check_layout(html_path, work):
    browser = chromium()
    if not browser:
        print("SKIP: chromium is not installed (optional test dependency: scripts/setup-debian.sh --with-optional installs it)")
        sys.exit(77)
    measured = work / "report-measured.html"
    html = html_path.read_text()
    measured.write_text(html.replace("</body>", MEASURE + "</body>") if "</body>" in html else html + MEASURE)
    with tempfile.TemporaryDirectory() as profile:
        r = run_chromium(browser, ["--window-size=1280,1000", "--virtual-time-budget=10000", "--dump-dom", measured.as_uri()], profile)
    m = re.search(r'<pre id="layout-result">(.*?)</pre>', r.stdout, re.S)
    if not m:
        sys.exit(f"chromium printed no measurement (exit {r.returncode}): {r.stderr.strip()[-500:]}")
    result = json.loads(m.group(1).replace("&lt;", "<").replace("&gt;", ">").replace("&quot;", '"').replace("&amp;", "&"))
    height = min(int(result["height"]) + 20, 32000)
    shot = work / "report.png"
    with tempfile.TemporaryDirectory() as profile:
        r = run_chromium(browser, [f"--window-size=1280,{height}", f"--screenshot={shot}", html_path.as_uri()], profile)
    if not shot.exists():
        sys.exit(f"chromium wrote no screenshot (exit {r.returncode}): {r.stderr.strip()[-500:]}")
    print(f"chromium: page {result['width']} x {result['height']} px, {result['svgs']} SVG plots; screenshot {shot} (1280 x {height})")
    problems = list(result["problems"])
    if result["width"] > 1280:
        problems.append(f"the page is {result['width']} px wide: it scrolls sideways in a 1280 px window")
    return problems


def main():
    if len(sys.argv) != 4 or sys.argv[1] not in ("size", "layout"):
        sys.exit(__doc__)
    mode, html, work = sys.argv[1], Path(sys.argv[2]) / "report.html", Path(sys.argv[3])
    if not html.exists():
        sys.exit(f"{html}: no report there (validate-hair-luts --out writes one)")
    work.mkdir(parents=True, exist_ok=True)
    problems = check_size(html) if mode == "size" else check_layout(html, work)
    for p in problems[:40]:
        print("clipped:" if mode == "layout" else "problem:", p)
    if len(problems) > 40:
        print(f"... and {len(problems) - 40} more")
    if problems:
        return 1
    print("report ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
