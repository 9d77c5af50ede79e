"""The help text tells the truth: the names it lists are the names the parser accepts (and lists
in its error messages), and the defaults it names are the ones a command uses."""
import json
import os
import re

import pytest

from imgutil import run, smooth_shape, write_points

NAMED = ["--method", "--parametrization", "--invariance"]


def help_line(cmd, opt):
    r = run(cmd, "--help")
    assert r.returncode == 0, r.stderr
    for line in r.stdout.splitlines():
        if line.strip().startswith(opt + " "):
            return line.strip()[len(opt):].split(None, 1)[1]
    raise AssertionError("no help line for %s in 'amscr %s --help'" % (opt, cmd))


def help_choices(cmd, opt):
    """The names of a 'a | b (default) | c' help line, and the one marked (default)."""
    text = help_line(cmd, opt).split(" (default:")[0]
    names, default = [], None
    for part in text.split("|"):
        name = part.split()[0]
        if "(default)" in part:
            default = name
        names.append(name)
    return names, default


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    d = tmp_path_factory.mktemp("help")
    s, t = d / "s.txt", d / "t.txt"
    write_points(s, smooth_shape(seed=0))
    write_points(t, [(1.3 * x + 0.4 * y + 5, -0.2 * x + 0.8 * y - 3) for x, y in smooth_shape(seed=0.3)])
    return s, t


def register_json(pair, *opts):
    r = run("register", pair[0], pair[1], "--json", *opts)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


@pytest.mark.parametrize("opt", NAMED)
def test_help_names_are_the_parsers(opt, pair):
    names, _ = help_choices("register", opt)
    assert len(names) >= 3
    r = run("register", pair[0], pair[1], opt, "no-such-name")
    assert r.returncode == 2
    m = re.search(r"expected (.*), got", r.stderr)
    assert m, r.stderr
    assert re.split(r", | or ", m.group(1)) == names
    for name in names:
        assert run("register", pair[0], pair[1], opt, name).returncode == 0, (opt, name)
        assert help_choices("search", opt)[0] == names


def test_help_defaults_are_the_commands(pair):
    default = register_json(pair)
    method = help_choices("register", "--method")[1]
    assert default["method"] == method
    param = help_choices("register", "--parametrization")[1]
    assert param == "whitened"
    assert register_json(pair, "--parametrization", param) == default
    others = [n for n in help_choices("register", "--parametrization")[0] if n != param]
    assert all(register_json(pair, "--parametrization", n)["distance"] != default["distance"] for n in others)
    inv = re.search(r"default: (\S+) for register", help_line("register", "--invariance")).group(1)
    assert register_json(pair, "--invariance", inv) == default
    points = re.search(r"default (\d+) for register", help_line("register", "--points")).group(1)
    assert default["samples"] == int(points)
    refine = re.search(r"^\s*(\d+) for register", run("register", "--help").stdout, re.M).group(1)
    assert register_json(pair, "--refine", refine) == default


def test_main_help_lists_every_command():
    r = run("--help")
    cmds = re.findall(r"^  (\w+) ", r.stdout.split("commands:")[1], re.M)
    cmds = [c for c in cmds if c != "amscr"]
    assert cmds == ["contour", "register", "search", "matrix", "eval", "index"]
    missing = run()
    assert missing.returncode == 2 and "contour, register, search, matrix, eval or index" in missing.stderr
    for c in cmds:
        assert run("help", c).stdout == run(c, "--help").stdout


def test_stage_names_are_the_parsers(pair):
    """--stage lists every stage it accepts, pixel_grid included, in its error and its help."""
    r = run("register", pair[0], pair[1], "--stage", "no_such=off")
    assert r.returncode == 2 and r.stdout == ""
    m = re.search(r"not a switchable stage \((.*)\)", r.stderr)
    assert m, r.stderr
    names = re.split(r", | or ", m.group(1))
    assert sorted(names) == ["despike", "even_spacing", "order", "pixel_grid", "polish", "recovery"]
    help_text = " ".join(run("register", "--help").stdout.split())
    for name in names:
        assert name in help_text, name
        assert run("register", pair[0], pair[1], "--stage", name + "=off").returncode == 0, name


def test_index_help_says_tracing_options_are_not_kept():
    """An index keeps no image-tracing option: the help and the docs say so, and no longer claim
    --add takes the build's --threshold."""
    from imgutil import REPO
    text = " ".join(run("index", "--help").stdout.split())
    assert "does not keep the image-tracing options (--threshold, --pixel-chain)" in text, text
    assert "--threshold included" not in text
    docs = " ".join(open(os.path.join(REPO, "docs", "collections.md")).read().split())
    assert "`--threshold` included" not in docs
    assert "`--threshold` and `--pixel-chain` are not stored in it" in docs
