"""Runs a tool as a child and measures its own peak memory (shared by slabbed.py and estimate.py)."""

import os
import resource
import signal


def peak_mib_of(args, work, file_size_limit=None):
    """Runs args[0] with args; returns (rc, stdout, stderr, peak RSS MiB) from getrusage of the
    child alone. stdout and stderr pass through files in `work`. file_size_limit: a full disk
    (writes past the limit fail with EFBIG)."""
    pid = os.fork()
    if pid == 0:
        if file_size_limit is not None:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (file_size_limit, file_size_limit))
        fd = os.open(os.path.join(work, "stdout.txt"), os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
        fe = os.open(os.path.join(work, "stderr.txt"), os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
        os.dup2(fd, 1)
        os.dup2(fe, 2)
        try:
            os.execv(args[0], args)
        finally:
            os._exit(127)
    _, status, usage = os.wait4(pid, 0)
    rc = os.waitstatus_to_exitcode(status)
    with open(os.path.join(work, "stdout.txt")) as f:
        out = f.read()
    with open(os.path.join(work, "stderr.txt")) as f:
        err = f.read()
    return rc, out, err, usage.ru_maxrss / 1024.0
