"""`amscr search --sheet FILE.png|svg` and `amscr eval --plot FILE.svg`."""
import re
import struct

import pytest

from imgutil import run
from test_collection import AFFINE
from test_protocols import make_manifest


def polygon_points(svg_fragment):
    pts = re.search(r'points="([^"]*)"', svg_fragment).group(1).split()
    return [tuple(float(v) for v in p.split(",")) for p in pts]


def bbox(pts):
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    return min(xs), min(ys), max(xs), max(ys)


def test_sheet_svg_draws_each_hit_registered_onto_the_query(tmp_path):
    m = make_manifest(tmp_path)
    q = tmp_path / "shapes" / "star_2.txt"
    out = tmp_path / "sheet.svg"
    r = run("search", q, m, "--top", "3", "--sheet", out, *AFFINE)
    assert r.returncode == 0, r.stderr
    svg = out.read_text()
    groups = re.findall(r'<g class="(query|hit)">(.*?)</g>', svg, re.S)
    assert [g[0] for g in groups] == ["query", "hit", "hit", "hit"]
    assert "star_2.txt" in groups[0][1] and ">1 star " in groups[1][1]
    for _, body in groups[1:]:
        polys = re.findall(r"<polygon[^>]*>", body)
        assert len(polys) == 2  # the query, and the hit registered onto it
        qb, hb = bbox(polygon_points(polys[0])), bbox(polygon_points(polys[1]))
        # affine copies under the affine group: the registered hit covers the query
        assert all(abs(a - b) < 4.0 for a, b in zip(qb, hb)), (qb, hb)


@pytest.mark.png
def test_sheet_png(tmp_path):
    m = make_manifest(tmp_path)
    out = tmp_path / "sheet.png"
    r = run("search", tmp_path / "shapes" / "blob_1.txt", m, "--top", "5", "--sheet", out, *AFFINE)
    assert r.returncode == 0, r.stderr
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    w, h = struct.unpack(">II", data[16:24])
    assert w == 2 * 12 + 4 * 240 and h == 2 * 12 + 2 * 264  # 6 tiles: two rows of up to 4


@pytest.mark.parametrize("args,msg", [
    (("search", "{q}", "{m}", "--sheet", "{t}/s.jpg"), "--sheet"),
    (("search", "{q}", "{m}", "--sheet", "{t}/missing/s.png"), "s.png"),
    (("eval", "{m}", "--plot", "{t}/p.png"), "--plot"),
])
def test_picture_bad_input(tmp_path, args, msg):
    m = make_manifest(tmp_path)
    a = [x.format(q=tmp_path / "shapes" / "star_1.txt", m=m, t=tmp_path) for x in args]
    r = run(*a, *AFFINE)
    assert r.returncode in (1, 2) and msg in r.stderr and r.stdout == ""
    assert not list(tmp_path.glob("s.*")) and not list(tmp_path.glob("p.*"))


def test_eval_plot_bars_and_precision_recall(tmp_path):
    m = make_manifest(tmp_path)
    out = tmp_path / "plot.svg"
    r = run("eval", m, "--plot", out, *AFFINE)
    assert r.returncode == 0, r.stderr
    svg = out.read_text()
    bars = re.findall(r'<rect x="[^"]*" y="[^"]*" width="([^"]*)"[^>]*><title>(\w+) ([^<]*)</title>', svg)
    assert len(bars) == 3 * 2  # 3 classes x (1-NN, bull's eye)
    assert all(float(w) == pytest.approx(300.0) for w, _, _ in bars)  # every score is 1 here
    pr = polygon_points(re.search(r'<polyline id="pr"[^>]*>', svg).group(0))
    assert len(pr) == 21
    ys = [p[1] for p in pr]
    assert ys == sorted(ys)  # interpolated precision never rises with recall (y grows downwards)


def test_eval_plot_split_protocol(tmp_path):
    m = make_manifest(tmp_path)
    out = tmp_path / "plot.svg"
    r = run("eval", m, "--protocol", "split", "--train", "1", "--plot", out, *AFFINE)
    assert r.returncode == 0, r.stderr
    assert "random split" in out.read_text()


def test_svg_text_of_odd_names_is_well_formed_xml(tmp_path):
    """Control characters and bytes that are not UTF-8 in file and class names: the SVGs stay
    well-formed XML, showing each control character as its control picture and each stray byte as
    U+FFFD (they were copied as they were: XML parsers refused the file)."""
    import os
    import xml.dom.minidom
    m = make_manifest(tmp_path)
    text = m.read_bytes().replace(b"\tstar\t", b"\tst\x01a\xffr&<\t")
    m.write_bytes(text)
    src = os.fsdecode(bytes(tmp_path) + b"/src\x1b\xfe.txt")
    with open(os.fsencode(src), "wb") as f:
        f.write((tmp_path / "shapes" / "star_2.txt").read_bytes())
    outs = {"o": tmp_path / "o.svg", "p": tmp_path / "p.svg", "s": tmp_path / "s.svg", "e": tmp_path / "e.svg"}
    r = run("register", src, tmp_path / "shapes" / "star_1.txt", "--overlay", outs["o"], "--plot", outs["p"],
            "--json")
    assert r.returncode == 0, r.stderr
    r = run("search", src, m, "--top", "3", "--sheet", outs["s"], "--json", *AFFINE)
    assert r.returncode == 0, r.stderr
    r = run("eval", m, "--plot", outs["e"], *AFFINE)
    assert r.returncode == 0, r.stderr
    for key, out in outs.items():
        doc = xml.dom.minidom.parse(str(out))
        texts = "".join(n.firstChild.data for n in doc.getElementsByTagName("text") if n.firstChild)
        if key in "ops":
            assert "src\u241b\ufffd.txt" in texts, key
        if key in "se":
            assert "st\u2401a\ufffdr&<" in texts, key


@pytest.mark.png
def test_sheet_png_of_many_hits_is_linear_in_memory(tmp_path):
    """A sheet of the query and 120 hits (31 rows of tiles, 984 x 8208 pixels): each tile is drawn in a raster
    of its own. A layer of the whole sheet per tile took 19 bytes a pixel of the sheet (160 MB
    here, 560 MB for --top 500) and time quadratic in the hits (--top 500 ran for minutes). The
    bound is on the growth over a small sheet's peak, so that it holds under ASan too."""
    import math
    from imgutil import run_peak_memory, write_points
    d = tmp_path / "many"
    d.mkdir()
    for k in range(120):
        a, s = 0.05 * k, 1.0 + 0.01 * k
        write_points(d / ("s%03d.txt" % k),
                     [(s * (40 + 8 * math.cos(3 * t)) * math.cos(t + a), (40 + 8 * math.cos(3 * t)) * math.sin(t + a))
                      for t in (2 * math.pi * i / 64 for i in range(64))])
    out = tmp_path / "sheet.png"
    rc, err, base_kib = run_peak_memory("search", d / "s000.txt", d, "--top", "3", "--sheet", out, *AFFINE)
    assert rc == 0, err
    rc, err, peak_kib = run_peak_memory("search", d / "s000.txt", d, "--top", "120", "--sheet", out, *AFFINE)
    assert rc == 0, err
    data = out.read_bytes()
    assert struct.unpack(">II", data[16:24]) == (2 * 12 + 4 * 240, 2 * 12 + 31 * 264)  # 121 tiles
    # beyond a 4-tile sheet's peak: 23 MiB (39 under ASan; 145 before, drawing on whole-sheet layers)
    assert peak_kib - base_kib < 64 * 1024, (base_kib, peak_kib)


def test_svg_labels_cut_on_characters_and_keep_their_start(tmp_path):
    """The sheet's class (9 characters) is cut between UTF-8 characters (it was cut at 9 bytes:
    U+FFFD, or a malformed SVG); a long class label of the eval plot, anchored at its end, keeps
    its start and ends with an ellipsis (its start was drawn off the picture); a long file name
    under a tile no longer runs into the next tile's."""
    import xml.dom.minidom
    m = make_manifest(tmp_path, with_group=False)
    long_class = "w" + "x" * 199
    m.write_text(m.read_text().replace("\tstar\n", "\tab\u65e5\u672c\u8a9e\u9ce5\n")
                 .replace("\twave\n", "\t%s\n" % long_class), encoding="utf-8")
    q = tmp_path / ("q" * 150 + ".txt")
    q.write_bytes((tmp_path / "shapes" / "star_2.txt").read_bytes())
    sheet, plot = tmp_path / "s.svg", tmp_path / "e.svg"
    r = run("search", q, m, "--top", "9", "--sheet", sheet, "--json", *AFFINE)
    assert r.returncode == 0, r.stderr
    r = run("eval", m, "--plot", plot, *AFFINE)
    assert r.returncode == 0, r.stderr

    def texts(path):
        doc = xml.dom.minidom.parse(str(path))
        return [n.firstChild.data for n in doc.getElementsByTagName("text") if n.firstChild]

    t = texts(sheet)
    assert any(s.startswith("1 ab\u65e5\u672c\u8a9e\u9ce5 ") for s in t), t
    assert not any("\ufffd" in s for s in t)
    assert "q" * 35 + "\u2026" in t
    t = texts(plot)
    assert "w" + "x" * 22 + "\u2026" in t and "star" not in t
