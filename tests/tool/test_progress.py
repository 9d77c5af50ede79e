"""Progress bars: on stderr when it is a terminal (a pty here), with the rate and the time left;
nothing on stderr when it is not."""
import os
import subprocess
import sys

import pytest

from imgutil import run, tool_path
from test_protocols import make_manifest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux") and sys.platform != "darwin",
                                reason="needs a pty")


def run_on_pty(*args):
    """Runs the tool with stderr on a pseudo-terminal; returns (code, stdout, terminal bytes)."""
    import pty
    master, slave = pty.openpty()
    p = subprocess.Popen([tool_path()] + [str(a) for a in args], stdout=subprocess.PIPE, stderr=slave,
                         stdin=subprocess.DEVNULL)
    os.close(slave)
    seen = b""
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:  # EIO: the child closed the terminal
            break
        if not chunk:
            break
        seen += chunk
    out = p.stdout.read()
    p.stdout.close()
    os.close(master)
    return p.wait(timeout=120), out.decode(), seen.decode("utf-8", "replace")


@pytest.mark.parametrize("cmd", [
    ("eval", "{m}", "--protocol", "nn"),
    ("matrix", "{m}", "-o", "-"),
    ("search", "{q}", "{m}"),
    ("search", "{q}", "{m}", "--no-rerank"),
    ("index", "{m}", "-o", "{t}/s.idx"),
])
def test_progress_on_a_terminal(tmp_path, cmd):
    m = make_manifest(tmp_path)
    q = tmp_path / "shapes" / "star_2.txt"
    args = [a.format(m=m, q=q, t=tmp_path) for a in cmd]
    code, out, term = run_on_pty(*args)
    assert code == 0 and out
    assert "amscr: matching [" in term and "/s" in term and " left" in term
    assert "9/9" in term or "81/81" in term or "100/100" in term  # the bar reaches its end
    assert term.endswith("\r\x1b[K")  # the line is cleared before the results are read
    if args[0] != "search" or "--no-rerank" not in args:
        assert "preparing shapes [" in term


def test_no_progress_without_a_terminal(tmp_path):
    m = make_manifest(tmp_path)
    for args in (("eval", m), ("matrix", m, "-o", "-"), ("search", tmp_path / "shapes" / "star_2.txt", m),
                 ("index", m, "-o", tmp_path / "s.idx")):
        r = run(*args)
        assert r.returncode == 0 and r.stderr == ""
