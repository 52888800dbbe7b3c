#!/usr/bin/env python3
"""Every code block of README.md and docs/**/*.md, run or built as written; links; performance tables.

Each fenced block needs a language tag. A block is handled by its tag and by a marker comment on
the line before it, `<!-- doc-test: ... -->`:

- `text` (or `console`, `output`): illustrative output, skipped.
- `sh`: run with bash -e in a scratch directory that looks like a checkout (build/release is the
  build tree under test, tables/ a copy, the rest links to the sources); the blocks of one
  document run in order in one directory, so a later block sees what an earlier one wrote.
  Marker `syntax (reason)`: checked with bash -n, and every ./scripts/... it names must exist and
  be executable (for commands that take minutes, such as the quick start's).
  Marker `python-pip`: run inside a fresh virtual environment (python3 -m venv
  --system-site-packages, Debian's numpy), pip without an index; later `python` blocks of the
  document then run with that environment's Python, i.e. the pip-installed module.
- `python`: run with that Python (or the build's module on PYTHONPATH) in the same directory.
- `json`: parsed (a fragment of members, `"key": ...`, is parsed inside braces).
- `cpp`, `cmake`: must carry the marker `file PATH` of a file in the repository and equal it
  byte for byte; the build compiles that file (a ctest runs it, the install test builds it
  against the installed package). Marker `file NAME` of a file not in the repository: the block
  is written to NAME in the scratch directory (a config the next blocks use).

Links: every relative link of these documents points to a file or folder that exists.

Performance: docs/performance.md holds the tables bench-hair-luts writes into docs/bench/, between
`<!-- bench: NAME -->` and `<!-- /bench -->`, with the machine NAME.json records and the command;
they must equal the files (--update-performance copies them again).

Usage: check_docs.py --source S --build B --work W [--python PY] [--only FILE...] [--update-performance]
"""

import argparse
import concurrent.futures
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

FENCE = re.compile(r"^```([A-Za-z0-9_+-]*)\s*$")
MARKER = re.compile(r"^<!--\s*doc-test:\s*(.*?)\s*-->\s*$")
SKIP = {"text", "console", "output"}
# A block's output, collected with its document's (documents run in parallel).
CAPTURE = {"stdout": subprocess.PIPE, "stderr": subprocess.STDOUT, "text": True, "errors": "replace"}
BENCH_COMMANDS = {
    "bench": "bench-hair-luts --out docs/bench --slices 80",
    "representations": "bench-hair-luts --representations-only --out docs/bench",
    "presets": "bench-hair-luts --only presets --out docs/bench",
    "pbrt-hair": "bench-hair-luts --only pbrt --out docs/bench",
}


def blocks(path):
    """(line, lang, marker, text) of every fenced block."""
    lines = path.read_text().split("\n")
    out, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        start, lang = i, m.group(1)
        j = i + 1
        while j < len(lines) and lines[j].rstrip() != "```":
            j += 1
        if j >= len(lines):
            raise SystemExit(f"{path}:{start + 1}: code block never closed")
        k = start - 1
        while k >= 0 and not lines[k].strip():
            k -= 1
        mk = MARKER.match(lines[k]) if k >= 0 else None
        out.append((start + 1, lang, mk.group(1) if mk else "", "\n".join(lines[i + 1:j]) + "\n"))
        i = j + 1
    return out


def bench_section(source, name):
    """The text docs/performance.md holds for bench file NAME (docs/bench/NAME.md and .json)."""
    bench = source / "docs" / "bench"
    md = (bench / f"{name}.md").read_text().split("\n")
    tables, current = [], []
    for line in md + [""]:
        if line.startswith("|"):
            current.append(line)
        elif current:
            tables.append("\n".join(current))
            current = []
    if name == "bench":
        tables = tables[:1]
    data = json.loads((bench / f"{name}.json").read_text())
    machine = data.get("machine") if isinstance(data, dict) else None
    out_dir = "docs/bench/" + os.path.dirname(name) if "/" in name else "docs/bench"
    base = os.path.basename(name)
    command = BENCH_COMMANDS.get(base, f"bench-hair-luts --only {base} --out docs/bench").replace("--out docs/bench", f"--out {out_dir}")
    if machine:
        head = f"Machine: {machine['cpu']}, {machine['cores']} cores; hairlut {machine['hairlut_version']}."
    else:
        head = f"Machine: not recorded in bench/{name}.json."
    head += f" Command: `{command}`. Files: [bench/{name}.md](bench/{name}.md), `.csv`, `.json`."
    return head + "\n\n" + "\n\n".join(tables)


def performance(source, update):
    path = source / "docs" / "performance.md"
    text = path.read_text()
    pattern = re.compile(r"(<!-- bench: (\S+) -->\n)(.*?)(<!-- /bench -->)", re.S)
    errors = []

    def replace(m):
        want = bench_section(source, m.group(2)) + "\n"
        if m.group(3) != want and not update:
            errors.append(f"docs/performance.md: the section of bench/{m.group(2)}.md differs from the file (run tests/check_docs.py --update-performance)")
        return m.group(1) + want + m.group(4)

    new = pattern.sub(replace, text)
    if update and new != text:
        path.write_text(new)
        print("updated docs/performance.md")
    return errors


def links(source, doc):
    errors = []
    for m in re.finditer(r"\]\(([^)\s]+)\)", doc.read_text()):
        target = m.group(1).split("#")[0]
        if not target or re.match(r"^[a-z]+:", target):
            continue
        if not (doc.parent / target).exists():
            errors.append(f"{doc.relative_to(source)}: link to a missing file: {m.group(1)}")
    return errors


def scratch(source, build, work):
    """A directory that looks like a checkout: tables copied (bakes write there), the rest linked."""
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    shutil.copytree(source / "tables", work / "tables")
    for name in ("schemas", "scripts", "docs", "examples", "python", "data", "LICENSE", "README.md", "CMakeLists.txt"):
        if (source / name).exists():
            (work / name).symlink_to(source / name)
    (work / "build").mkdir()
    (work / "build" / "release").symlink_to(build)
    return work


def fixtures(source, build, directory, text, env, log):
    """A block that opens a shipped config's file by its bare name (h5py.File("hairlut-NAME.h5"))
    gets it: tables/configs/NAME.json baked into the block's directory first."""
    for name in sorted(set(re.findall(r"[\"'](hairlut-([\w.-]+)\.h5)[\"']", text))):
        file, config = name[0], source / "tables" / "configs" / f"{name[1]}.json"
        if not (directory / file).exists() and config.exists():
            log(f"baking {config.name} for {file}")
            r = subprocess.run([str(build / "tools" / "bake-hair-luts" / "bake-hair-luts"), "--config", str(config), "--output-dir", str(directory),
                                "--quiet", "--threads", "2"], env=env, **CAPTURE)
            log(r.stdout)
            r.check_returncode()


def run_document(source, build, work, doc, python, env_base, log):
    errors = []
    directory = None
    python_now, python_env = python, dict(env_base)
    for line, lang, marker, text in blocks(doc):
        where = f"{doc.relative_to(source)}:{line}"
        if not lang:
            errors.append(f"{where}: code block without a language tag (use text for output)")
            continue
        if lang in SKIP:
            continue
        file_marker = marker[5:].strip() if marker.startswith("file ") else ""
        if lang in ("cpp", "cmake", "c++") or (file_marker and (source / file_marker).exists()):
            if not file_marker or not (source / file_marker).is_file():
                errors.append(f"{where}: a {lang} block must be a file of the repository (<!-- doc-test: file PATH -->), built by the build")
            elif (source / file_marker).read_text() != text:
                errors.append(f"{where}: differs from {file_marker} (the document must show the file as it is)")
            continue
        if lang == "json":
            try:
                json.loads(text)
            except ValueError:
                try:
                    json.loads("{" + text + "}")
                except ValueError as e:
                    errors.append(f"{where}: not JSON: {e}")
                    continue
        if directory is None:
            directory = scratch(source, build, work / doc.stem)
        if file_marker:
            (directory / file_marker).write_text(text)
            continue
        if lang == "json":
            continue
        if lang in ("sh", "bash"):
            if marker.startswith("syntax"):
                r = subprocess.run(["bash", "-n"], input=text, text=True, capture_output=True)
                if r.returncode != 0:
                    errors.append(f"{where}: bash -n: {r.stderr.strip()}")
                for script in re.findall(r"(?<![\w/])(\./scripts/[\w.-]+)", text):
                    if not os.access(source / script, os.X_OK):
                        errors.append(f"{where}: {script} is not an executable file")
                log(f"{where}: syntax checked")
                continue
            env = dict(env_base)
            if marker.startswith("python-pip"):
                venv = directory / "venv"
                subprocess.run([python, "-m", "venv", "--system-site-packages", str(venv)], check=True)
                env["PATH"] = f"{venv / 'bin'}:{env['PATH']}"
                env["PIP_NO_INDEX"] = "1"
                env["HAIRLUT_BUILD_DIR"] = str(build)
                env.pop("PYTHONPATH", None)
                python_now, python_env = str(venv / "bin" / "python3"), dict(env)
            log(f"{where}: sh\n{text}")
            r = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", text], cwd=directory, env=env, timeout=900, **CAPTURE)
            log(r.stdout)
            if r.returncode != 0:
                errors.append(f"{where}: the sh block exits {r.returncode}")
            continue
        if lang == "python":
            fixtures(source, build, directory, text, env_base, log)
            log(f"{where}: python ({python_now})\n{text}")
            r = subprocess.run([python_now, "-"], input=text, cwd=directory, env=python_env, timeout=900, **CAPTURE)
            log(r.stdout)
            if r.returncode != 0:
                errors.append(f"{where}: the python block exits {r.returncode}")
            continue
        errors.append(f"{where}: no rule for a {lang} block")
    return errors


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", type=Path, default=Path(__file__).resolve().parent.parent)
    ap.add_argument("--build", type=Path)
    ap.add_argument("--work", type=Path)
    ap.add_argument("--python", default="/usr/bin/python3")
    ap.add_argument("--jobs", type=int, default=2, help="documents run at once (default 2)")
    ap.add_argument("--only", nargs="*", help="documents to run (paths relative to the source); default: all")
    ap.add_argument("--update-performance", action="store_true", help="copy the bench tables into docs/performance.md and stop")
    a = ap.parse_args()
    source = a.source.resolve()
    if a.update_performance:
        performance(source, True)
        return 0
    docs = [source / "README.md"] + sorted((source / "docs").rglob("*.md"))
    errors = performance(source, False)
    for d in docs:
        errors += links(source, d)
    if not a.build or not a.work:
        for e in errors:
            print("error:", e, file=sys.stderr)
        print(f"links and performance tables only (--build and --work run the blocks): {len(errors)} problems")
        return 1 if errors else 0
    build = a.build.resolve()
    python_dir = build / "python"
    env = dict(os.environ)
    env["PYTHONPATH"] = str(python_dir) + (":" + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    # python3 in the blocks is the Python the module was built for.
    shim = a.work.resolve() / "bin"
    shim.mkdir(parents=True, exist_ok=True)
    if not (shim / "python3").exists():
        (shim / "python3").symlink_to(a.python)
    env["PATH"] = f"{shim}:{env.get('PATH', '/usr/bin:/bin')}"
    # Documents are independent (each has its own scratch checkout), so two run at once; each one's
    # output is collected and printed whole, in document order.
    def one(d):
        out = []
        errs = run_document(source, build, a.work.resolve(), d, a.python, env, lambda text: out.append(text.rstrip("\n")) if text else None)
        return out, errs

    chosen = [d for d in docs if not a.only or str(d.relative_to(source)) in a.only]
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        for out, errs in pool.map(one, chosen):
            print("\n".join(out), flush=True)
            errors += errs
    for e in errors:
        print("error:", e, file=sys.stderr)
    print(f"{len(docs)} documents, {len(errors)} problems")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
