#!/usr/bin/env python3
"""Hostile-input and fault probes of the hairlut tools, generated here (not fixed files).

Usage: hostile.py PROBE BAKE VALIDATE WORKDIR

Every probe runs a tool with a time limit and checks: no crash (no death by a signal the tool did
not ask for, no sanitizer report), no hang (the limit), a one-line `tool: error: ...` message and
the documented exit code, and no file left where none may be. Probes:
  long-strings   pattern-checked config strings of 30k .. 1M characters
  config-files   /dev/zero, a directory, a FIFO-less device, an oversized file, deep nesting
  corrupt-files  truncated and byte-flipped .h5 and .exr, loaded by the validator
  metadata       HDF5 attributes altered or deleted with h5py: the validator refuses, naming them
  exr-metadata   OpenEXR header text attributes altered in place: refused, naming them
  format-version a newer major format version is refused; an older major (1.x) or a newer minor one is read
  disk-full      a bake under a file-size limit (ulimit -f): one-line I/O error, exit 1
  max-points     validate --max-points 0 and 1: refused with exit 2
  signals        SIGINT/SIGTERM/SIGHUP stop bake, validate, bench and compare within a second
                 (130/143/129)
  stale-temps    a SIGKILLed bake's temporaries are removed by the next bake; user files that look
                 like temporaries (any pid) survive; no temporary is written through a link
  storage        external storage (a copy, /dev/zero, a FIFO, a relative path), virtual datasets,
                 external and soft links, never-written values: refused before any value is read
  heap-scan      a file packed with overlapping global-heap signatures is screened in linear time
  resources      --memory-budget above the machine's memory, --check on an unwritable output, a
                 bake waiting for another's directory lock (who holds it, --lock-timeout)
  config-sweep   every numeric config field at extreme values (sweep.py): refused in one line or
                 baked into a file the validator reads
  eta-near-one   eta = 1 + 1e-7 bakes and validates in bounded time
  concurrent     two bakes of different configs into one directory leave one consistent set
"""
import json
import os
import resource
import shutil
import signal
import subprocess
import sys
import time

PROBE, BAKE, VALIDATE, WORK = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
TOOLS = os.path.dirname(os.path.dirname(os.path.abspath(BAKE)))  # the other tools sit beside the baker
failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL: " + msg)


def tiny_config(name="hostile", basename="t", directory="out", **extra):
    c = {
        "name": name,
        "lobes": {"explicit": ["R", "TT"], "residual": True},
        "quadrature": {"order": 32},
        "tables": {
            "np": {"axes": {"theta_d": {"count": 3, "range_deg": [0, 60]}, "phi": {"count": 5},
                            "sigma_a": {"count": 2, "range": [0, 1]}, "beta": {"count": 1, "range_deg": [10, 10]}}},
        },
        "output": {"directory": directory, "basename": basename, "formats": ["hdf5", "exr"]},
    }
    c.update(extra)
    return c


def write_json(path, doc):
    with open(path, "w") as f:
        json.dump(doc, f)


def run(args, timeout=60, preexec=None, **kw):
    """Runs a tool; returns (rc, stdout, stderr, seconds). A timeout is a failure (hang)."""
    t0 = time.monotonic()
    try:
        p = subprocess.run(args, capture_output=True, text=True, timeout=timeout, preexec_fn=preexec, errors="replace", **kw)
    except subprocess.TimeoutExpired:
        fail("hang: %s did not finish in %d s" % (" ".join(args)[:200], timeout))
        return None, "", "", timeout
    return p.returncode, p.stdout, p.stderr, time.monotonic() - t0


def expect_error(what, args, code, must_contain=None, timeout=60, preexec=None):
    rc, out, err, secs = run(args, timeout, preexec)
    if rc is None:
        return
    tool = os.path.basename(args[0])
    lines = [l for l in err.splitlines() if l.strip()]
    if rc < 0:
        fail("%s: crashed with signal %d" % (what, -rc))
    elif rc != code:
        fail("%s: exit %d, expected %d; stderr: %s" % (what, rc, code, err[-300:]))
    elif len(lines) != 1 or not lines[0].startswith(tool + ": error: "):
        fail("%s: expected one line '%s: error: ...', got %d lines: %s" % (what, tool, len(lines), err[:300]))
    elif must_contain and must_contain not in lines[0]:
        fail("%s: message lacks %r: %s" % (what, must_contain, lines[0][:300]))
    else:
        print("ok  %-60s exit %d in %.2f s: %s" % (what, rc, secs, lines[0][:140]))


def bake(config_path, extra=(), timeout=120):
    rc, out, err, _ = run([BAKE, "--config", config_path, "--quiet", "--force"] + list(extra), timeout)
    if rc != 0:
        raise SystemExit("setup bake failed (%s): %s" % (rc, err))


def probe_long_strings():
    for n in (30000, 200000, 1000000):
        s = "a" * n
        cases = {
            "name": tiny_config(name=s),
            "output.basename": tiny_config(basename=s),
            "lobe name": tiny_config(lobes={"explicit": ["T" + "R" * n + "T"], "residual": True}),
            "tilt_deg key": tiny_config(lobes={"explicit": ["R"], "residual": True, "tilt_deg": {"T" + "R" * n + "T": 1.0}}),
            "tilt_deg key (no match)": tiny_config(lobes={"explicit": ["R"], "residual": True, "tilt_deg": {s: 1.0}}),
            "description": tiny_config(description=s),
        }
        for key, cfg in cases.items():
            path = os.path.join(WORK, "long.json")
            write_json(path, cfg)
            expect_error("%s of %d characters (--check)" % (key, n), [BAKE, "--config", path, "--check"], 2)


def probe_config_files():
    expect_error("--config /dev/zero", [BAKE, "--config", "/dev/zero", "--check"], 2, "not a regular file", timeout=20)
    expect_error("--config a directory", [BAKE, "--config", WORK, "--check"], 2, "is a directory")
    big = os.path.join(WORK, "big.json")
    with open(big, "w") as f:
        f.write('{"name": "x", "description": "')
        f.write("a" * (17 << 20))
        f.write('"}')
    expect_error("--config of 17 MiB", [BAKE, "--config", big, "--check"], 2, "too large")
    os.remove(big)
    huge = os.path.join(WORK, "huge.json")
    # 1e14 values (400 TB): larger than any machine's memory and disk, so refused up front even
    # though tables over the memory budget are baked slab by slab.
    write_json(huge, tiny_config(tables={"np": {"axes": {
        "theta_d": {"count": 10000, "range_deg": [0, 85]}, "phi": {"count": 10000},
        "sigma_a": {"count": 1000, "range": [0, 5]}, "beta": {"count": 1000, "range_deg": [1, 30]}}}}))
    expect_error("tables of 1e14 values (--check)", [BAKE, "--config", huge, "--check"], 1, "more than this machine has")
    expect_error("tables of 1e14 values", [BAKE, "--config", huge, "--quiet"], 1, "more than this machine has")
    deep = os.path.join(WORK, "deep.json")
    for depth in (10000, 1000000):
        with open(deep, "w") as f:
            f.write('{"name": "x", "tables": ' + "[" * depth + "]" * depth + "}")
        expect_error("arrays nested %d deep" % depth, [BAKE, "--config", deep, "--check"], 2)
        with open(deep, "w") as f:
            f.write('{"name": "x", "lobes": ' + '{"a":' * depth + "1" + "}" * depth + "}")
        expect_error("objects nested %d deep" % depth, [BAKE, "--config", deep, "--check"], 2)


def baked_tiny():
    d = os.path.join(WORK, "tiny")
    if not os.path.exists(os.path.join(d, "out", "t.json")):
        os.makedirs(d, exist_ok=True)
        write_json(os.path.join(d, "c.json"), tiny_config())
        bake(os.path.join(d, "c.json"))
    return os.path.join(d, "out")


def probe_corrupt_files():
    out = baked_tiny()
    for ext in ("h5", "exr"):
        data = open(os.path.join(out, "t." + ext), "rb").read()
        bad = os.path.join(WORK, "bad." + ext)
        cuts = sorted(set([0, 8, 64, len(data) // 3, len(data) // 2, len(data) - 1]))
        for cut in cuts:
            with open(bad, "wb") as f:
                f.write(data[:cut])
            expect_error("%s truncated to %d bytes" % (ext, cut), [VALIDATE, bad, "--quiet", "--out", os.path.join(WORK, "r")], 2)
        step = max(1, len(data) // 40)
        for pos in range(16, len(data), step):
            b = bytearray(data)
            b[pos] ^= 0x5A
            with open(bad, "wb") as f:
                f.write(bytes(b))
            rc, o, err, secs = run([VALIDATE, bad, "--quiet", "--max-points", "200", "--out", os.path.join(WORK, "r")], 120)
            if rc is None:
                continue
            lines = [l for l in err.splitlines() if l.strip()]
            if rc < 0:
                fail("%s byte %d flipped: crashed with signal %d" % (ext, pos, -rc))
            elif rc == 0:
                fail("%s byte %d flipped: accepted silently" % (ext, pos))
            elif rc == 2 and len(lines) != 1:
                fail("%s byte %d flipped: %d lines of error: %s" % (ext, pos, len(lines), err[:300]))
        print("ok  %s: every flipped byte refused or detected" % ext)


def h5_copy():
    src = os.path.join(baked_tiny(), "t.h5")
    dst = os.path.join(WORK, "mut.h5")
    shutil.copyfile(src, dst)
    return dst


def probe_metadata():
    import h5py
    import numpy as np
    mutations = [
        ("root eta = 2", lambda f: f.attrs.__setitem__("eta", 2.0), "eta"),
        ("root eta = NaN", lambda f: f.attrs.__setitem__("eta", float("nan")), "eta"),
        ("root eta = 'abc'", lambda f: f.attrs.__setitem__("eta", "abc"), "eta"),
        ("root model deleted", lambda f: f.attrs.__delitem__("model"), "model"),
        ("root model changed", lambda f: f.attrs.__setitem__("model", "marschner2003"), "model"),
        ("root lobes deleted", lambda f: f.attrs.__delitem__("lobes"), "lobes"),
        ("root config_hash deleted", lambda f: f.attrs.__delitem__("config_hash"), "config_hash"),
        ("root hairlut_version deleted", lambda f: f.attrs.__delitem__("hairlut_version"), "hairlut_version"),
        ("np/TT lobe = TRT", lambda f: f["np/TT"].attrs.__setitem__("lobe", "TRT"), "lobe"),
        ("np/TT p = 7", lambda f: f["np/TT"].attrs.__setitem__("p", np.int64(7)), "attribute p"),
        ("np/TT units deleted", lambda f: f["np/TT"].attrs.__delitem__("units"), "units"),
        ("np/TT quantity deleted", lambda f: f["np/TT"].attrs.__delitem__("quantity"), "quantity"),
        ("np/TT DIMENSION_LIST deleted", lambda f: f["np/TT"].attrs.__delitem__("DIMENSION_LIST"), "DIMENSION_LIST"),
        ("np/phi units changed", lambda f: f["np/phi"].attrs.__setitem__("units", "degree"), "units"),
        ("np/phi range changed", lambda f: f["np/phi"].attrs.__setitem__("range", np.array([0.0, 1.0])), "range"),
        ("hairlut_format_version = 3.0", lambda f: set_fixed(f, "hairlut_format_version", b"3.0"), "newer"),
        ("hairlut_format_version deleted", lambda f: f.attrs.__delitem__("hairlut_format_version"), "hairlut_format_version"),
    ]
    # The unaltered copy passes the same loader (so that a refusal below is the mutation's doing).
    path = h5_copy()
    rc, _, err, _ = run([VALIDATE, path, "--quiet", "--max-points", "200", "--out", os.path.join(WORK, "r")], 300)
    if rc not in (0, 1):
        fail("unaltered copy: exit %s: %s" % (rc, err[:300]))
    for what, mutate, name in mutations:
        path = h5_copy()
        with h5py.File(path, "r+") as f:
            mutate(f)
        expect_error(what, [VALIDATE, path, "--quiet", "--max-points", "200", "--out", os.path.join(WORK, "r")], 2, name)


def probe_exr_metadata():
    """OpenEXR header attributes (no checksum in the format) altered in place, same length."""
    data = open(os.path.join(baked_tiny(), "t.exr"), "rb").read()
    for name in (b"hairlut.layout", b"hairlut.channels", b"hairlut.quantity", b"hairlut.axis.phi", b"hairlut.version"):
        at = data.find(name + b"\x00string\x00")
        if at < 0:
            fail("no attribute %s in the EXR file" % name.decode())
            continue
        value = at + len(name) + 8 + 4  # name, NUL, "string", NUL, 4-byte size
        b = bytearray(data)
        b[value] = ord("#") if b[value] != ord("#") else ord("%")
        path = os.path.join(WORK, "mut.exr")
        with open(path, "wb") as f:
            f.write(bytes(b))
        expect_error("EXR %s altered" % name.decode(), [VALIDATE, path, "--quiet", "--max-points", "200", "--out", os.path.join(WORK, "r")],
                     2, name.decode())


def set_fixed(f, key, value):
    import h5py
    import numpy as np
    if key in f.attrs:
        del f.attrs[key]
    tid = h5py.h5t.C_S1.copy()
    tid.set_size(len(value))
    tid.set_strpad(h5py.h5t.STR_NULLPAD)
    tid.set_cset(h5py.h5t.CSET_UTF8)
    a = h5py.h5a.create(f.id, key.encode(), tid, h5py.h5s.create(h5py.h5s.SCALAR))
    a.write(np.array(value, dtype="S%d" % len(value)), mtype=tid)


def probe_format_version():
    import h5py
    for version, ok in (("1.0", True), ("1.7", True), ("2.0", True), ("2.7", True), ("3.0", False), ("0.9", False), ("10.3", False),
                        ("1", False), ("x.y", False)):
        path = h5_copy()
        with h5py.File(path, "r+") as f:
            set_fixed(f, "hairlut_format_version", version.encode())
        args = [VALIDATE, path, "--quiet", "--max-points", "200", "--out", os.path.join(WORK, "r")]
        if ok:
            rc, _, err, _ = run(args, 300)
            if rc not in (0, 1):
                fail("format version %s: not read (exit %s): %s" % (version, rc, err[:300]))
            else:
                print("ok  format version %s is read" % version)
        else:
            expect_error("format version %s" % version, args, 2, "format")


def probe_disk_full():
    d = os.path.join(WORK, "full")
    os.makedirs(d, exist_ok=True)
    write_json(os.path.join(d, "c.json"), tiny_config(tables={
        "np": {"axes": {"theta_d": {"count": 24, "range_deg": [0, 85]}, "phi": {"count": 64},
                        "sigma_a": {"count": 6, "range": [0, 5]}, "beta": {"count": 6, "range_deg": [0.5, 30], "spacing": "log"}}}},
        output={"directory": "out", "basename": "t", "formats": ["hdf5", "exr"], "hdf5": {"compression": 0}, "exr": {"compression": "none"}}))
    # Limits that stop the HDF5 file, and (with a deflated HDF5 file smaller than the EXR) one that
    # lets the HDF5 file through and stops the EXR writer.
    cfg = json.load(open(os.path.join(d, "c.json")))
    cfg["output"]["hdf5"] = {"compression": 6}
    write_json(os.path.join(d, "c.json"), cfg)
    bake(os.path.join(d, "c.json"))
    h5_size, exr_size = (os.path.getsize(os.path.join(d, "out", "t." + e)) for e in ("h5", "exr"))
    shutil.rmtree(os.path.join(d, "out"))
    limits = [4, 64, h5_size // 2048]
    if h5_size + 4096 < exr_size:
        limits.append((h5_size + exr_size) // 2048)
    else:
        fail("the probe needs an HDF5 file smaller than the EXR file (%d, %d bytes)" % (h5_size, exr_size))
    for limit_kib in limits:
        def limit():
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit_kib * 1024, limit_kib * 1024))
            signal.signal(signal.SIGXFSZ, signal.SIG_DFL)  # the tool itself must ignore it
        expect_error("bake with a %d KiB file-size limit" % limit_kib, [BAKE, "--config", os.path.join(d, "c.json"), "--quiet", "--force"],
                     1, timeout=120, preexec=limit)
        left = os.listdir(os.path.join(d, "out")) if os.path.isdir(os.path.join(d, "out")) else []
        if left:
            fail("disk full at %d KiB: files left: %s" % (limit_kib, left))


def probe_max_points():
    path = os.path.join(baked_tiny(), "t.h5")
    for n in ("0", "1"):
        expect_error("validate --max-points %s" % n, [VALIDATE, path, "--max-points", n, "--out", os.path.join(WORK, "r")], 2, "max-points")


def slow_config(d):
    os.makedirs(d, exist_ok=True)
    cfg = tiny_config(quadrature={"method": "adaptive", "order": 64}, tables={
        "np": {"axes": {"theta_d": {"count": 40, "range_deg": [0, 85]}, "phi": {"count": 128},
                        "sigma_a": {"count": 16, "range": [0, 5]}, "beta": {"count": 16, "range_deg": [0.5, 30], "spacing": "log"}}}})
    write_json(os.path.join(d, "c.json"), cfg)
    return os.path.join(d, "c.json")


def probe_signals():
    d = os.path.join(WORK, "sig")
    cfg = slow_config(d)
    # A file whose validation takes several seconds: the shipped default tables.
    h5 = os.path.join(d, "default.h5")
    shutil.copyfile(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tables", "default", "hairlut-default.h5"), h5)
    codes = {signal.SIGINT: 130, signal.SIGTERM: 143, signal.SIGHUP: 129}
    for tool, args in (("bake", [BAKE, "--config", cfg, "--quiet", "--force"]),
                       ("validate", [VALIDATE, "--config", cfg, "--quiet", "--out", os.path.join(d, "r")]),
                       ("validate file", [VALIDATE, h5, "--quiet", "--out", os.path.join(d, "r2")]),
                       ("bench", [os.path.join(TOOLS, "bench-hair-luts", "bench-hair-luts"), "--quick", "--quiet", "--out", os.path.join(d, "bench")]),
                       ("compare", [os.path.join(TOOLS, "compare-hair-models", "compare-hair-models"), "--quiet", "--phi-samples", "20000",
                                    "--out", os.path.join(d, "compare")])):
        for sig, code in codes.items():
            p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            time.sleep(1.0)
            if p.poll() is not None:
                fail("%s finished before the signal; make the probe slower" % tool)
                continue
            t0 = time.monotonic()
            p.send_signal(sig)
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
                fail("%s ignored %s" % (tool, signal.Signals(sig).name))
                continue
            secs = time.monotonic() - t0
            if p.returncode != code:
                fail("%s %s: exit %d, expected %d" % (tool, signal.Signals(sig).name, p.returncode, code))
            elif secs > 1.5:
                fail("%s %s: stopped after %.2f s (more than a second)" % (tool, signal.Signals(sig).name, secs))
            else:
                print("ok  %-14s %-8s exit %d after %.2f s" % (tool, signal.Signals(sig).name, p.returncode, secs))
            out = os.path.join(d, "out")
            left = [n for n in os.listdir(out)] if os.path.isdir(out) else []
            if any(".tmp-" in n for n in left):
                fail("%s %s: temporaries left: %s" % (tool, signal.Signals(sig).name, left))


def kill_at_first_temporary(cfg_path, out_dir, attempts=5):
    """Runs a bake and SIGKILLs it as soon as one of its temporaries appears (a hard stop while
    writing); returns the pid of the killed bake, or None if it always finished first."""
    before = set(os.listdir(out_dir))
    for _ in range(attempts):
        p = subprocess.Popen([BAKE, "--config", cfg_path, "--quiet", "--force"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        tail = ".tmp-%d" % p.pid
        while p.poll() is None:
            if any(n.endswith(tail) for n in set(os.listdir(out_dir)) - before):
                p.kill()
                p.wait()
                if any(n.endswith(tail) for n in set(os.listdir(out_dir)) - before):
                    return p.pid
                break
        p.wait()
    return None


def probe_stale_temps():
    d = os.path.join(WORK, "stale")
    shutil.rmtree(d, ignore_errors=True)
    out = os.path.join(d, "out")
    os.makedirs(out)
    slow = json.load(open(slow_config(d)))
    slow["output"] = {"directory": out, "basename": "t", "formats": ["hdf5"], "hdf5": {"compression": 9}}
    slow["quadrature"] = {"order": 16}
    write_json(os.path.join(d, "c.json"), slow)
    # A pid that is surely dead: a child that has exited and been reaped.
    dead = subprocess.Popen(["true"])
    dead.wait()
    # The user's files that merely look like temporaries: never removed, whatever their "pid".
    user = ["t.h5.tmp-keep", "t-draft.tmp-x", "t.h5.tmp-%d" % dead.pid, "t.exr.tmp-%d" % dead.pid, "t.h5.tmp-%d" % os.getpid(),
            "t.h5.0123456789abcdef.tmp-%d" % dead.pid, "t.json.tmp-"]
    for n in user:
        with open(os.path.join(out, n), "wb") as f:
            f.write(b"user data")
    # Symbolic links to a file of the user's at the names the baker used to pick for itself (pids
    # are handed out in turn: the next processes are likely to get these).
    victim = os.path.join(d, "victim")
    with open(victim, "wb") as f:
        f.write(b"precious")
    links = ["t.h5.tmp-%d" % (dead.pid + k) for k in range(1, 40)]
    for n in links:
        os.symlink(victim, os.path.join(out, n))
    before = set(os.listdir(out))
    killed = kill_at_first_temporary(os.path.join(d, "c.json"), out)
    if killed is None:
        fail("the bake always finished before its temporary was seen; make the probe slower")
    bake(os.path.join(d, "c.json"), timeout=300)
    left = sorted(n for n in set(os.listdir(out)) - before if n.endswith(".tmp-%d" % killed)) if killed else []
    if left:
        fail("temporaries of a killed bake kept: %s" % left)
    lost = [n for n in user if not os.path.exists(os.path.join(out, n)) or open(os.path.join(out, n), "rb").read() != b"user data"]
    if lost:
        fail("user files removed or changed by the stale-temporary cleanup: %s" % lost)
    if any(not os.path.islink(os.path.join(out, n)) for n in links):
        fail("a symbolic link planted at a temporary name was removed or replaced")
    if open(victim, "rb").read() != b"precious":
        fail("a file was written through a symbolic link planted at a temporary name")
    if not left and not lost and killed:
        print("ok  the killed bake's temporaries removed; %d user files that look like temporaries kept" % len(user))


def replace_dataset(f, name, make):
    """Replaces dataset `name` by make(group, basename, values, dtype) with the same attributes."""
    import numpy as np
    old = f[name]
    values, dtype, attrs = old[()], old.dtype, []
    for k in old.attrs.keys():
        aid = old.attrs.get_id(k)
        attrs.append((k, old.attrs[k], aid.shape, aid.dtype))
    group, base = name.rsplit("/", 1)
    del f[name]
    new = make(f[group], base, values, dtype)
    if new is None:
        return
    for k, v, shape, adt in attrs:
        if k == "DIMENSION_LIST":
            continue
        new.attrs.create(k, v, shape=shape, dtype=adt)
    axes = json.loads(new.attrs["hairlut_table"])["axes"]
    for i, a in enumerate(axes):
        new.dims[i].attach_scale(f[group][a["name"]])


def probe_storage():
    """Tables whose values live outside the file (external storage, external and soft links,
    virtual datasets) or are not stored at all (fill values): refused before any value is read,
    without following the storage, in bounded time and memory."""
    import h5py
    import numpy as np
    src = os.path.join(baked_tiny(), "t.h5")
    other = os.path.join(WORK, "other.h5")
    shutil.copyfile(src, other)
    raw = os.path.join(WORK, "tt.raw")
    fifo = os.path.join(WORK, "fifo")
    if not os.path.exists(fifo):
        os.mkfifo(fifo)

    def external_to(target, write_values):
        def make(g, base, values, dtype):
            if write_values:
                with open(target, "wb") as out:
                    out.write(values.astype(dtype).tobytes())
            return g.create_dataset(base, shape=values.shape, dtype=dtype, external=[(target, 0, h5py.h5f.UNLIMITED)])
        return make

    def virtual(g, base, values, dtype):
        layout = h5py.VirtualLayout(shape=values.shape, dtype=dtype)
        layout[...] = h5py.VirtualSource(other, "np/TT", shape=values.shape)
        return g.create_virtual_dataset(base, layout)

    def ext_link(g, base, values, dtype):
        g[base] = h5py.ExternalLink(other, "/np/TT")
        return None

    def soft_link(g, base, values, dtype):
        g[base] = h5py.SoftLink("/np/R")
        return None

    def fill_only(g, base, values, dtype):
        return g.create_dataset(base, shape=values.shape, dtype=dtype, chunks=values.shape, compression="gzip")

    cases = [("external storage with the same values (checksum matches)", external_to(raw, True), "external"),
             ("external storage in /dev/zero", external_to("/dev/zero", False), "external"),
             ("external storage in a FIFO", external_to(fifo, False), "external"),
             ("external storage in ../../etc/hostname", external_to("../../etc/hostname", False), "external"),
             ("virtual dataset over another file's table", virtual, "virtual"),
             ("external link to another file's table", ext_link, "external link"),
             ("soft link to another table", soft_link, "soft link"),
             ("values never written (fill values)", fill_only, "not stored")]
    for what, make, needle in cases:
        path = h5_copy()
        with h5py.File(path, "r+") as f:
            replace_dataset(f, "np/TT", make)
        for tool in ([VALIDATE, path, "--quiet", "--max-points", "200", "--out", os.path.join(WORK, "r")],):
            expect_error(what, tool, 2, needle, timeout=30)
    # A link anywhere in the file (not only at a table) is refused too.
    path = h5_copy()
    with h5py.File(path, "r+") as f:
        f["extra"] = h5py.ExternalLink(fifo, "/x")
    expect_error("an external link beside the tables", [VALIDATE, path, "--quiet", "--out", os.path.join(WORK, "r")], 2, "external link", timeout=30)


def probe_heap_scan():
    """Files packed with global-heap signatures (each a candidate collection the screen walks) are
    screened without a hang: candidates every 16 bytes that claim the rest of the file, and
    walkable 32-byte collections every 32 bytes, appended to a valid file."""
    data = open(os.path.join(baked_tiny(), "t.h5"), "rb").read()
    for mib in (1, 8):
        n = (mib << 20) // 16
        # Nested collections, each walkable in one record: the header at 16 i claims 32 (n - i)
        # bytes; its first record is the next header, whose size field makes it skip exactly to
        # the end of the enclosing collection. Reading each candidate whole is quadratic.
        m = n // 2
        nested = b"".join(b"GCOL\x01\x00\x00\x00" + (32 * (m - i)).to_bytes(8, "little") for i in range(m))
        nested += b"\x00" * 8 + (16).to_bytes(8, "little") + b"\x00" * (16 * m - 16)
        claiming = b"".join(b"GCOL\x01\x00\x00\x00" + (16 * (n - i)).to_bytes(8, "little") for i in range(n))
        walkable = (b"GCOL\x01\x00\x00\x00" + (32).to_bytes(8, "little") + b"\x00" * 8 + (16).to_bytes(8, "little")) * (n // 2)
        for what, body in (("nested", nested), ("claiming the rest of the file", claiming), ("walkable", walkable)):
            path = os.path.join(WORK, "gcol.h5")
            with open(path, "wb") as f:
                f.write(data + body)
            rc, _, err, secs = run([VALIDATE, path, "--quiet", "--max-points", "200", "--out", os.path.join(WORK, "r")], 60)
            if rc is None:
                continue
            if rc < 0 or rc not in (0, 1, 2):
                fail("%d MiB of heap signatures %s: exit %d: %s" % (mib, what, rc, err[-300:]))
            else:
                print("ok  %d MiB of heap signatures %s: exit %d in %.2f s" % (mib, what, rc, secs))


def probe_eta_near_one():
    d = os.path.join(WORK, "eta")
    os.makedirs(d, exist_ok=True)
    for eta in (1.0000001, 1.000001):
        cfg = tiny_config(fiber={"eta": eta})
        write_json(os.path.join(d, "c.json"), cfg)
        rc, _, err, secs = run([BAKE, "--config", os.path.join(d, "c.json"), "--quiet", "--force"], 120)
        if rc != 0:
            fail("eta %r: bake exit %s: %s" % (eta, rc, err[:300]))
            continue
        rc, _, err, secs = run([VALIDATE, os.path.join(d, "out", "t.h5"), "--quiet", "--max-points", "2000", "--out", os.path.join(d, "r")], 120)
        if rc is None:
            continue
        if rc < 0 or rc not in (0, 1, 2):
            fail("eta %r: validate exit %s: %s" % (eta, rc, err[:300]))
        else:
            print("ok  eta %r: validate exit %d in %.1f s %s" % (eta, rc, secs, err.strip()[:140]))


def probe_concurrent():
    d = os.path.join(WORK, "conc")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    a = slow_config(os.path.join(d, "a"))
    cfg_a = json.load(open(a))
    cfg_a["output"]["directory"] = os.path.join(d, "out")
    cfg_a["quadrature"] = {"order": 32}
    # Small tables: the bakes only need to overlap (both start together and write at the end).
    cfg_a["tables"]["np"]["axes"]["beta"]["count"] = 6
    cfg_a["tables"]["np"]["axes"]["sigma_a"]["count"] = 6
    cfg_b = json.loads(json.dumps(cfg_a))
    cfg_b["name"] = "other"
    cfg_b["tables"]["np"]["axes"]["phi"]["count"] = 96
    write_json(os.path.join(d, "a.json"), cfg_a)
    write_json(os.path.join(d, "b.json"), cfg_b)
    for round_ in range(3):
        pa = subprocess.Popen([BAKE, "--config", os.path.join(d, "a.json"), "--quiet", "--force"], stderr=subprocess.PIPE, text=True)
        pb = subprocess.Popen([BAKE, "--config", os.path.join(d, "b.json"), "--quiet", "--force"], stderr=subprocess.PIPE, text=True)
        ra, rb = pa.wait(timeout=300), pb.wait(timeout=300)
        ea, eb = pa.stderr.read(), pb.stderr.read()
        if ra < 0 or rb < 0:
            fail("concurrent bakes crashed: %d %d" % (ra, rb))
        side = json.load(open(os.path.join(d, "out", "t.json")))
        rc, _, err, _ = run([VALIDATE, os.path.join(d, "out", "t.h5"), "--quiet", "--max-points", "200", "--out", os.path.join(d, "r")], 300)
        import h5py
        with h5py.File(os.path.join(d, "out", "t.h5")) as f:
            h5_hash = f.attrs["config_hash"]
        exr = subprocess.run(["exrheader", os.path.join(d, "out", "t.exr")], capture_output=True, text=True).stdout
        exr_ok = side["config_hash"] in exr
        if h5_hash != side["config_hash"] or not exr_ok:
            fail("round %d: mixed set (h5 %s, sidecar %s, exr has sidecar hash: %s); exits %d %d: %s %s"
                 % (round_, h5_hash, side["config_hash"], exr_ok, ra, rb, ea[-200:], eb[-200:]))
        else:
            print("ok  round %d: consistent set of config %s (exits %d, %d)" % (round_, side["config_hash"], ra, rb))


def probe_resources():
    """--memory-budget cannot exceed the machine; --check refuses an output directory the bake
    could not write; a bake waiting for another's directory lock says who holds it and honours
    --lock-timeout."""
    import fcntl
    d = os.path.join(WORK, "res")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.join(d, "out"))
    cfg = os.path.join(d, "c.json")
    write_json(cfg, tiny_config(directory=os.path.join(d, "out")))
    expect_error("--memory-budget 1e12", [BAKE, "--config", cfg, "--memory-budget", "1e12", "--check"], 2, "memory")
    with open(os.path.join(d, "plain"), "w") as f:
        f.write("x")
    expect_error("--check with the output under a file", [BAKE, "--config", cfg, "--output-dir", os.path.join(d, "plain", "sub"), "--check"],
                 1, "not a directory")
    fd = os.open(os.path.join(d, "out"), os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX)
    try:
        expect_error("bake while another process holds the directory's lock (--lock-timeout 1)",
                     [BAKE, "--config", cfg, "--force", "--quiet", "--lock-timeout", "1"], 1, "pid %d" % os.getpid(), timeout=60)
        p = subprocess.Popen([BAKE, "--config", cfg, "--force"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        time.sleep(3.0)
        fcntl.flock(fd, fcntl.LOCK_UN)
        err = p.communicate(timeout=120)[1]
        if p.returncode != 0:
            fail("bake after the lock was released: exit %d: %s" % (p.returncode, err[-300:]))
        elif "held by pid %d" % os.getpid() not in err:
            fail("a bake waiting for the lock did not say who holds it: %r" % err[-300:])
        else:
            print("ok  a waiting bake says who holds the lock and goes on once it is released")
    finally:
        os.close(fd)


def probe_config_sweep():
    """Every numeric config field of the schema at extreme values (sweep.py, its quick value set):
    refused in one line, or baked into a file the validator reads; never a crash, a hang, or a
    file its own loader refuses."""
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path.insert(0, here)
    import sweep
    sweep.VALUES[:] = sweep.QUICK_VALUES
    results, unreached = sweep.sweep(BAKE, VALIDATE, os.path.join(WORK, "sweep"), os.path.join(here, "..", "..", "schemas",
                                                                                             "hairlut-config.schema.json"))
    for kind, label, why in results:
        if kind not in ("refused", "baked"):
            fail("%s: %s: %s" % (kind, label, why))
    if unreached:
        fail("fields no base config reaches: %s" % unreached)
    print("ok  " + sweep.summary(results, unreached))


PROBES = {
    "long-strings": probe_long_strings, "config-files": probe_config_files, "corrupt-files": probe_corrupt_files,
    "metadata": probe_metadata, "exr-metadata": probe_exr_metadata, "format-version": probe_format_version, "disk-full": probe_disk_full,
    "max-points": probe_max_points, "signals": probe_signals, "stale-temps": probe_stale_temps,
    "eta-near-one": probe_eta_near_one, "concurrent": probe_concurrent, "storage": probe_storage, "heap-scan": probe_heap_scan,
    "config-sweep": probe_config_sweep, "resources": probe_resources,
}

os.makedirs(WORK, exist_ok=True)
os.chdir(WORK)
PROBES[PROBE]()
if failures:
    print("%d failure(s)" % len(failures))
    sys.exit(1)
print("all probes passed")
