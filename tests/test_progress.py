"""Progress lines (parksteer.progress.note) from processes that share one stderr: a first diagnosis's builders and
replay workers each say what they wait for, and a reader of the pipe must get their lines whole."""

from __future__ import annotations

import subprocess
import sys

WRITERS = """
import os
from parksteer.progress import note
line = "another process is building the model 668f1fc5656eae9f15de: waiting for it"
children = []
for _ in range(4):
    pid = os.fork()
    if pid == 0:
        for _ in range(500):
            note(line)
        os._exit(0)
    children.append(pid)
for pid in children:
    os.waitpid(pid, 0)
"""


def test_lines_of_processes_sharing_stderr_arrive_whole():
    """Four forked processes write 500 notes each into one pipe: every line read is one note, none split or joined
    (each note is one write of the line and its newline; print's two writes interleave here by the thousand)."""
    done = subprocess.run([sys.executable, "-c", WRITERS], capture_output=True, text=True, timeout=60, check=True)
    lines = done.stderr.splitlines()
    assert len(lines) == 2000
    assert set(lines) == {"another process is building the model 668f1fc5656eae9f15de: waiting for it"}
