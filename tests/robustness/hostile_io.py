"""Probes of hostile.py that concern files and leftovers: stale temporaries and planted links,
tables stored outside their file, global-heap screening, resource guards and the config sweep.
Each takes the hostile module `h` (its tools, work directory and helpers)."""
import json
import os
import shutil
import subprocess
import sys
import time


def kill_at_first_temporary(h, cfg_path, out_dir, attempts=5):
    """Runs a h.bake and SIGKILLs it as soon as one of its temporaries appears (a hard stop while
    writing); returns the pid of the killed h.bake, or None if it always finished first."""
    before = set(os.listdir(out_dir))
    for _ in range(attempts):
        p = subprocess.Popen([h.BAKE, "--config", cfg_path, "--quiet", "--force"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
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


def probe_stale_temps(h):
    d = os.path.join(h.WORK, "stale")
    shutil.rmtree(d, ignore_errors=True)
    out = os.path.join(d, "out")
    os.makedirs(out)
    slow = json.load(open(h.slow_config(d)))
    slow["output"] = {"directory": out, "basename": "t", "formats": ["hdf5"], "hdf5": {"compression": 9}}
    slow["quadrature"] = {"order": 16}
    h.write_json(os.path.join(d, "c.json"), slow)
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
    killed = kill_at_first_temporary(h, os.path.join(d, "c.json"), out)
    if killed is None:
        h.fail("the bake always finished before its temporary was seen; make the probe slower")
    h.bake(os.path.join(d, "c.json"), timeout=300)
    left = sorted(n for n in set(os.listdir(out)) - before if n.endswith(".tmp-%d" % killed)) if killed else []
    if left:
        h.fail("temporaries of a killed bake kept: %s" % left)
    lost = [n for n in user if not os.path.exists(os.path.join(out, n)) or open(os.path.join(out, n), "rb").read() != b"user data"]
    if lost:
        h.fail("user files removed or changed by the stale-temporary cleanup: %s" % lost)
    if any(not os.path.islink(os.path.join(out, n)) for n in links):
        h.fail("a symbolic link planted at a temporary name was removed or replaced")
    if open(victim, "rb").read() != b"precious":
        h.fail("a file was written through a symbolic link planted at a temporary name")
    if not left and not lost and killed:
        print("ok  the killed bake's temporaries removed; %d user files that look like temporaries kept" % len(user))


def replace_dataset(h, f, name, make):
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


def probe_storage(h):
    """Tables whose values live outside the file (external storage, external and soft links,
    virtual datasets) or are not stored at all (fill values): refused before any value is read,
    without following the storage, in bounded time and memory."""
    import h5py
    import numpy as np
    src = os.path.join(h.baked_tiny(), "t.h5")
    other = os.path.join(h.WORK, "other.h5")
    shutil.copyfile(src, other)
    raw = os.path.join(h.WORK, "tt.raw")
    fifo = os.path.join(h.WORK, "fifo")
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
        path = h.h5_copy()
        with h5py.File(path, "r+") as f:
            replace_dataset(h, f, "np/TT", make)
        for tool in ([h.VALIDATE, path, "--quiet", "--max-points", "200", "--no-search", "--out", os.path.join(h.WORK, "r")],):
            h.expect_error(what, tool, 2, needle, timeout=30)
    # A link anywhere in the file (not only at a table) is refused too.
    path = h.h5_copy()
    with h5py.File(path, "r+") as f:
        f["extra"] = h5py.ExternalLink(fifo, "/x")
    h.expect_error("an external link beside the tables", [h.VALIDATE, path, "--quiet", "--out", os.path.join(h.WORK, "r")], 2, "external link", timeout=30)


def probe_heap_scan(h):
    """Files packed with global-heap signatures (each a candidate collection the screen walks) are
    screened without a hang: candidates every 16 bytes that claim the rest of the file, and
    walkable 32-byte collections every 32 bytes, appended to a valid file."""
    data = open(os.path.join(h.baked_tiny(), "t.h5"), "rb").read()
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
            path = os.path.join(h.WORK, "gcol.h5")
            with open(path, "wb") as f:
                f.write(data + body)
            rc, _, err, secs = h.run([h.VALIDATE, path, "--quiet", "--max-points", "200", "--no-search", "--out", os.path.join(h.WORK, "r")], 60)
            if rc is None:
                continue
            if rc < 0 or rc not in (0, 1, 2):
                h.fail("%d MiB of heap signatures %s: exit %d: %s" % (mib, what, rc, err[-300:]))
            else:
                print("ok  %d MiB of heap signatures %s: exit %d in %.2f s" % (mib, what, rc, secs))


def probe_resources(h):
    """--memory-budget cannot exceed the machine; --check refuses an output directory the h.bake
    could not write; a h.bake waiting for another's directory lock says who holds it and honours
    --lock-timeout."""
    import fcntl
    d = os.path.join(h.WORK, "res")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.join(d, "out"))
    cfg = os.path.join(d, "c.json")
    h.write_json(cfg, h.tiny_config(directory=os.path.join(d, "out")))
    h.expect_error("--memory-budget 1e12", [h.BAKE, "--config", cfg, "--memory-budget", "1e12", "--check"], 2, "memory")
    with open(os.path.join(d, "plain"), "w") as f:
        f.write("x")
    h.expect_error("--check with the output under a file", [h.BAKE, "--config", cfg, "--output-dir", os.path.join(d, "plain", "sub"), "--check"],
                 1, "not a directory")
    fd = os.open(os.path.join(d, "out"), os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX)
    try:
        h.expect_error("bake while another process holds the directory's lock (--lock-timeout 1)",
                     [h.BAKE, "--config", cfg, "--force", "--quiet", "--lock-timeout", "1"], 1, "pid %d" % os.getpid(), timeout=60)
        p = subprocess.Popen([h.BAKE, "--config", cfg, "--force"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        time.sleep(3.0)
        fcntl.flock(fd, fcntl.LOCK_UN)
        err = p.communicate(timeout=120)[1]
        if p.returncode != 0:
            h.fail("bake after the lock was released: exit %d: %s" % (p.returncode, err[-300:]))
        elif "held by pid %d" % os.getpid() not in err:
            h.fail("a bake waiting for the lock did not say who holds it: %r" % err[-300:])
        else:
            print("ok  a waiting bake says who holds the lock and goes on once it is released")
    finally:
        os.close(fd)


def config_sweep(h, bases):
    """Every numeric config field of the schema at extreme values (sweep.py), each place a field
    lands in at one value, the next in turn: refused in one line, or baked into a file the
    validator reads; never a crash, a hang, or a file its own loader refuses."""
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path.insert(0, here)
    import sweep
    sweep.PER_PLACE = 1
    sweep.SEARCH = False
    results, unreached = sweep.sweep(h.BAKE, h.VALIDATE, os.path.join(h.WORK, "sweep"), os.path.join(here, "..", "..", "schemas",
                                                                                             "hairlut-config.schema.json"), bases)
    for kind, label, why in results:
        if kind not in ("refused", "baked"):
            h.fail("%s: %s: %s" % (kind, label, why))
    if unreached:
        h.fail("fields no base config reaches: %s" % unreached)
    print("ok  " + sweep.summary(results, unreached))


def probe_sidecars(h):
    """Sidecars (the .json beside a set) that are large, deep or hold a long "files" list: a 60 MB
    sidecar of nested objects is read in bounded memory (only the fields the loader uses are kept);
    one over the size cap, one nested too deeply and one whose "files" list is too long are refused
    in one line naming the sidecar."""
    import threading
    d = os.path.join(h.WORK, "sidecars")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    src = h.baked_tiny()
    for ext in ("h5", "json"):
        shutil.copyfile(os.path.join(src, "t." + ext), os.path.join(d, "t." + ext))
    side_path = os.path.join(d, "t.json")
    side = json.load(open(side_path))
    validate = [h.VALIDATE, os.path.join(d, "t.h5"), "--quiet", "--max-points", "200", "--no-search", "--out", os.path.join(d, "r")]

    def peak(args):
        """(rc, stderr, peak RSS of this child alone in MiB, seconds); killed after 120 s (a hang)."""
        t0 = time.monotonic()
        with open(os.path.join(d, "stderr.txt"), "w+") as ef:
            p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=ef)
            timer = threading.Timer(120, p.kill)
            timer.start()
            _, status, usage = os.wait4(p.pid, 0)
            timer.cancel()
            p.returncode = os.waitstatus_to_exitcode(status)
            ef.seek(0)
            err = ef.read()
        if p.returncode == -9:
            h.fail("hang: %s did not finish in 120 s" % " ".join(args)[:200])
        return p.returncode, err, usage.ru_maxrss / 1024.0, time.monotonic() - t0

    rc, err, base, _ = peak(validate)
    if rc not in (0, 1):
        h.fail("the unaltered set: validate exit %s: %s" % (rc, err[-300:]))
        return
    # 60 MB of nested objects (20 levels each) in a field the loader does not use.
    unit = "{\"a\":" * 20 + "0" + "}" * 20
    count = (60 << 20) // (len(unit) + 1)
    # Written in pieces: a child's peak RSS counts this process's memory at the fork.
    text = json.dumps(side)
    with open(side_path, "w") as f:
        f.write(text[:-1] + ', "padding": [' + unit)
        piece = ("," + unit) * 4096
        for _ in range(count // 4096):
            f.write(piece)
        f.write("]}")
    mb = os.path.getsize(side_path) / 1e6
    rc, err, top, secs = peak(validate)
    if rc not in (0, 1):
        h.fail("a %.0f MB sidecar of nested objects: validate exit %s: %s" % (mb, rc, err[-300:]))
    elif top > base + 400:
        h.fail("a %.0f MB sidecar of nested objects: peak RSS %.0f MiB against %.0f MiB with the written sidecar" % (mb, top, base))
    else:
        print("ok  a %.0f MB sidecar of nested objects: exit %d in %.2f s, peak RSS %.0f MiB (written sidecar: %.0f MiB)" % (mb, rc, secs, top, base))
    # Over the size cap (256 MiB; refused before reading, so a sparse file will do).
    with open(side_path, "w") as f:
        f.truncate(257 << 20)
    h.expect_error("a 257 MiB sidecar", validate, 2, "t.json: the set's sidecar is 257.0 MiB", timeout=30)
    for what, text, phrase in (("a sidecar nested 100000 levels deep", text[:-1] + ', "x": ' + "[" * 100000 + "]" * 100000 + "}", "nests deeper"),
                               ("a sidecar whose files list holds 100000 entries",
                                json.dumps(dict(side, files=side["files"] + [{"path": "x%d" % i} for i in range(100000)])), "holds more than")):
        with open(side_path, "w") as f:
            f.write(text)
        h.expect_error(what, validate, 2, "t.json: " + "the set's sidecar " + phrase, timeout=30)


# The dual-scattering base apart: validating one of its bakes takes about 12 s of CPU (the direct
# dual-scattering integrals), three times that under the sanitizers, so it runs in the release
# build only and every other base in the sanitizer build.
PROBES = {"stale-temps": probe_stale_temps, "storage": probe_storage, "heap-scan": probe_heap_scan, "resources": probe_resources,
          "sidecars": probe_sidecars,
          "config-sweep": lambda h: config_sweep(h, "-ds"), "config-sweep-ds": lambda h: config_sweep(h, "ds")}
