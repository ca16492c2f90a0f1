"""``python -m rigger`` run as a pipeline would: in a child process of this interpreter, and what it left in a
folder."""
import os
import subprocess
import sys


def run_cli(*args, env=None, timeout=300):
    """The finished child process of ``python -m rigger ARGS`` (output captured as text); ``env`` adds variables."""
    return subprocess.run([sys.executable, "-m", "rigger", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, env=None if env is None else {**os.environ, **env})


def files_below(folder):
    """Every file and folder below ``folder`` (hidden ones too), as sorted POSIX paths relative to it."""
    return sorted(path.relative_to(folder).as_posix() for path in folder.rglob("*"))
