"""Collections: `amscr matrix` (.tsv and .npy agree), `amscr eval` on a manifest and a
folder, `amscr search`, class names from file names."""
import json
import math
import os
import struct
import subprocess
from pathlib import Path

import pytest

from imgutil import (affine, blank, fill_rect, image_bytes, img_ext, rasterize, read_points, run, smooth_shape,
                     tool_path, write_points)

MAPS = [((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
        ((0.9, 0.4, 10.0), (-0.3, 1.1, -5.0)),
        ((0.6, -0.5, -3.0), (0.7, 0.8, 2.0))]


# Retrieval commands default to the library's retrieval preset (the shape channel, re-ranking);
# these collections are affine-distorted copies: --paper is the AMSCR distance alone in the
# affine group, no refinement, no re-ranking.
AFFINE = ("--paper",)


def test_retrieval_defaults_and_rerank(manifest):
    """The defaults (shape channel + re-ranking) run, and --rerank changes the matrix."""
    import json as _json
    j = _json.loads(run("eval", manifest, "--json").stdout)
    assert j["n"] == 9 and len(j["topk"]) == 8
    assert j["bullseye"] == 1.0  # the channel's affine share ranks affine copies together
    a = run("matrix", manifest, "-o", "-", "--no-rerank").stdout
    b = run("matrix", manifest, "-o", "-", "--rerank", "3,10").stdout
    assert a != b
    assert run("eval", manifest, "--rerank", "0").returncode == 2
    assert run("eval", manifest, "--rerank", "3,0").returncode == 2


def test_paper_is_the_explicit_options(manifest):
    explicit = ("--invariance", "affine", "--no-rerank", "--refine", "0", "--channel-weight", "0")
    assert run("matrix", manifest, "-o", "-", "--paper").stdout == run("matrix", manifest, "-o", "-", *explicit).stdout


def test_retrieval_options(manifest):
    base = run("matrix", manifest, "-o", "-").stdout
    for opts in (("--fast",), ("--affine-share", "0.5"), ("--channel-weight", "0.5")):
        r = run("matrix", manifest, "-o", "-", *opts)
        assert r.returncode == 0, r.stderr
        assert r.stdout != base, opts
    assert run("matrix", manifest, "-o", "-", "--fast").stdout == \
        run("matrix", manifest, "-o", "-", "--affine-share", "0").stdout
    for bad in (("--channel-weight", "1.5"), ("--affine-share", "-0.1"), ("--channel-weight", "x")):
        r = run("matrix", manifest, "-o", "-", *bad)
        assert r.returncode == 2 and bad[0] in r.stderr
    assert run("register", "a.txt", "b.txt", "--fast").returncode == 2  # a retrieval option


def test_search_scores_self_zero(manifest, tmp_path):
    """After re-ranking a member's own score is 0 and the others lie in (0, 1]."""
    q = tmp_path / "shapes" / "wave_2.txt"
    j = json.loads(run("search", q, manifest, "--top", "9", "--json").stdout)
    res = j["results"]
    assert res[0]["file"].endswith("wave_2.txt") and res[0]["distance"] == 0.0
    assert [x["class"] for x in res[:3]] == ["WAVE"] * 3
    assert all(0.0 < x["distance"] <= 1.0 for x in res[1:])


def base_shapes():
    star = []
    for i in range(200):
        t = 2 * math.pi * i / 200
        r = 1 + 0.35 * math.cos(5 * t) + 0.05 * math.sin(2 * t)
        star.append((50 * r * math.cos(t), 50 * r * math.sin(t)))
    return {"blob": smooth_shape(200, 0), "wave": smooth_shape(200, 2.5), "star": star}


@pytest.fixture
def manifest(tmp_path):
    d = tmp_path / "shapes"
    d.mkdir()
    rows = ["file\tclass"]
    for name, pts in base_shapes().items():
        for k, m in enumerate(MAPS, 1):
            rel = "shapes/%s_%d.txt" % (name, k)
            write_points(tmp_path / rel, affine(m, pts))
            rows.append("%s\t%s" % (rel, name.upper()))
    mf = tmp_path / "manifest.tsv"
    mf.write_text("\n".join(rows) + "\n")
    return mf


def read_npy(path):
    data = open(path, "rb").read()
    assert data[:6] == b"\x93NUMPY" and data[6:8] == b"\x01\x00"
    hlen = struct.unpack("<H", data[8:10])[0]
    assert (10 + hlen) % 64 == 0
    header = data[10:10 + hlen].decode("latin1")
    assert header.endswith("\n")
    d = eval(header)  # a Python literal, as numpy writes it
    assert d["descr"] == "<f8" and d["fortran_order"] is False
    n, m = d["shape"]
    vals = struct.unpack("<%dd" % (n * m), data[10 + hlen:])
    return [list(vals[i * m:(i + 1) * m]) for i in range(n)]


def read_tsv(path):
    rows = []
    for line in open(path):
        if line.startswith("#"):
            continue
        rows.append([float(v) for v in line.split("\t")])
    return rows


def test_matrix_tsv_equals_npy(manifest, tmp_path):
    tsv, npy, names = tmp_path / "d.tsv", tmp_path / "d.npy", tmp_path / "names.tsv"
    r = run("matrix", manifest, "-o", tsv, "--names", names, "--threads", "2")
    assert r.returncode == 0, r.stderr
    r = run("matrix", manifest, "-o", npy, "--threads", "1")
    assert r.returncode == 0, r.stderr
    a, b = read_tsv(tsv), read_npy(npy)
    assert len(a) == 9 and all(len(row) == 9 for row in a)
    assert a == b  # %.17g text round-trips exactly; thread counts give identical results
    assert all(a[i][i] == 0 for i in range(9))
    lines = names.read_text().splitlines()
    assert lines[0] == "file\tclass" and lines[1] == "shapes/blob_1.txt\tBLOB" and len(lines) == 10
    try:
        import numpy
    except ImportError:
        return
    assert numpy.array_equal(numpy.load(npy), numpy.loadtxt(tsv))


def test_search_of_a_member_without_rerank_is_its_matrix_row(tmp_path):
    """Without re-ranking, a search for a file of the collection (the member rule) prints its row
    of `matrix --no-rerank`, whose shape channel takes each pair from the lower index to the
    higher: a folder, its index and an index built --no-rerank alike, order and distances."""
    names = ["blob-1.txt", "blob-2.txt", "blob-3.txt", "star-1.txt", "star-2.txt", "star-3.txt", "wave-1.txt",
             "wave-2.txt", "wave-3.txt"]
    d = folder_of_points(tmp_path / "set", names)
    for k, name in enumerate(names):  # unequal warps: the two directions of a pair differ
        pts = [(x + 3 * math.sin(0.7 * k + 0.05 * i), y) for i, (x, y) in enumerate(read_points((d / name).read_text()))]
        write_points(d / name, pts)
    D = tmp_path / "D.tsv"
    assert run("matrix", d, "-o", D, "--no-rerank").returncode == 0
    rows = [[float(v) for v in line.split("\t")] for line in D.read_text().splitlines()[1:]]
    idx, idx0 = tmp_path / "s.idx", tmp_path / "s0.idx"
    assert run("index", d, "-o", idx).returncode == 0 and run("index", d, "-o", idx0, "--no-rerank").returncode == 0
    for coll in (d, idx, idx0):
        for i, name in enumerate(names):
            r = run("search", d / name, coll, "--no-rerank", "--json", "--top", len(names))
            assert r.returncode == 0, r.stderr
            res = json.loads(r.stdout)["results"]
            want = sorted(range(len(names)), key=lambda j: (rows[i][j], j))
            assert [h["index"] for h in res] == want, (coll, name)
            assert all(abs(h["distance"] - rows[i][h["index"]]) <= 1e-12 for h in res), (coll, name, res, rows[i])


def test_matrix_stdout(manifest):
    r = run("matrix", manifest, "-o", "-")
    assert r.returncode == 0, r.stderr
    rows = [ln for ln in r.stdout.splitlines() if not ln.startswith("#")]
    assert len(rows) == 9


def test_eval_manifest_json(manifest):
    # the collection holds affine-distorted copies: the affine group, plain pairwise distances
    r = run("eval", manifest, "--json", "--ranks", "2", *AFFINE)
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert j["n"] == 9 and j["classes"] == 3
    assert j["bullseye"] == 1.0
    assert j["topk"] == [9, 9]
    assert j["nn_accuracy"] == 1.0
    assert j["seconds"] >= 0


def test_eval_default_ranks_clamped(manifest):
    j = json.loads(run("eval", manifest, "--json").stdout)
    assert len(j["topk"]) == 8  # 10 by default, at most n - 1


@pytest.mark.parametrize("protocol,keys", [("bullseye", {"bullseye"}), ("topk", {"topk"}),
                                           ("nn", {"nn_accuracy"})])
def test_eval_protocols(manifest, protocol, keys):
    r = run("eval", manifest, "--json", "--protocol", protocol)
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert {"bullseye", "topk", "nn_accuracy"} & set(j) == keys
    assert {"n", "classes", "seconds"} <= set(j)


def test_eval_human(manifest):
    r = run("eval", manifest)
    assert r.returncode == 0, r.stderr
    assert "bull's eye" in r.stdout and "top-k" in r.stdout and "1-NN" in r.stdout


def test_eval_folder_classes_from_names(tmp_path):
    d = tmp_path / "imgs"
    d.mkdir()
    for name, pts in base_shapes().items():
        for k, m in enumerate(MAPS, 1):
            q = [(1.2 * x + 100, 1.2 * y + 100) for x, y in affine(m, pts)]
            fn = "%s-%d%s" % (name, k, img_ext())
            (d / fn).write_bytes(image_bytes(rasterize(q, 200, 200), fn))
    (d / "manifest.tsv").write_text("ignored\n")  # not a shape: skipped in a folder
    (d / "notes.md").write_text("# not a shape\n")
    r = run("eval", d, "--json", *AFFINE)
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert j["n"] == 9 and j["classes"] == 3
    assert j["nn_accuracy"] == 1.0


def test_search(manifest, tmp_path):
    q = tmp_path / "query.txt"
    write_points(q, affine(((0.7, 0.2, 1.0), (0.1, 1.3, 2.0)), base_shapes()["wave"]))
    r = run("search", q, manifest, "--top", "3", "--json", *AFFINE)
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert [x["class"] for x in j["results"]] == ["WAVE"] * 3
    assert [x["rank"] for x in j["results"]] == [1, 2, 3]
    d = [x["distance"] for x in j["results"]]
    assert d == sorted(d)
    r = run("search", q, manifest)
    assert r.returncode == 0 and "WAVE" in r.stdout


def test_bad_collection_member(manifest, tmp_path):
    (tmp_path / "shapes" / "star_2.txt").write_text("1 2\nbroken\n")
    r = run("eval", manifest)
    assert r.returncode == 1
    assert len(r.stderr.splitlines()) == 1 and "star_2.txt" in r.stderr
    out = tmp_path / "m.npy"
    r = run("matrix", manifest, "-o", out)
    assert r.returncode == 1 and not out.exists()


@pytest.mark.parametrize("text,needle", [("name\tlabel\na.txt\tx\n", "'file'"), ("file\tclass\n", "no shapes"),
                                         ("file\tclass\na.txt\n", "line 2"), ("", "empty")])
def test_bad_manifest(tmp_path, text, needle):
    mf = tmp_path / "m.tsv"
    mf.write_text(text)
    r = run("eval", mf)
    assert r.returncode == 1
    assert len(r.stderr.splitlines()) == 1 and "m.tsv" in r.stderr and needle in r.stderr, r.stderr


def test_empty_folder(tmp_path):
    r = run("eval", tmp_path)
    assert r.returncode == 1 and "no shapes" in r.stderr


@pytest.mark.png
def test_bundled_collection():
    from imgutil import REPO
    d = os.path.join(REPO, "examples", "collection")
    if not os.path.isdir(d):
        pytest.skip("examples/ not generated")
    j = json.loads(run("eval", d, "--json").stdout)
    assert j["n"] == 12 and j["classes"] == 4


def test_quiet_without_terminal(manifest, tmp_path):
    for args in (["eval", manifest], ["matrix", manifest, "-o", tmp_path / "m.tsv"]):
        r = run(*args)
        assert r.returncode == 0 and r.stderr == ""  # no progress bar when stderr is not a terminal


def test_progress_on_terminal(manifest):
    pty = pytest.importorskip("pty")
    import subprocess
    from imgutil import tool_path
    master, slave = pty.openpty()
    p = subprocess.run([tool_path(), "eval", str(manifest), "--json"], stdout=subprocess.PIPE, stderr=slave)
    os.close(slave)
    err = b""
    try:
        while True:
            chunk = os.read(master, 65536)
            if not chunk:
                break
            err += chunk
    except OSError:
        pass
    os.close(master)
    assert p.returncode == 0
    json.loads(p.stdout)  # stdout stays clean
    assert b"matching" in err and b"100%" in err


def test_shapes_prepared_on_threads(manifest, tmp_path):
    """A collection is decoded and prepared on threads: the matrix is the same for every thread
    count, and a collection with bad shapes fails naming the first bad one in its order, with
    the message a load on one thread gives (a bad point list: a failed decode; a collinear one:
    a failed preparation), however many threads load it."""
    one = run("matrix", manifest, "-o", "-", "--threads", "1").stdout
    for t in ("2", "3", "8"):
        assert run("matrix", manifest, "-o", "-", "--threads", t).stdout == one, t
    (tmp_path / "shapes" / "line.txt").write_text("".join("%d %d\n" % (i, 2 * i) for i in range(12)))
    (tmp_path / "shapes" / "bad.txt").write_text("1 2\nthree four\n")
    rows = manifest.read_text().splitlines()
    for first, later in (("line.txt", "bad.txt"), ("bad.txt", "line.txt")):
        mf = tmp_path / ("m-%s.tsv" % first)
        bad = rows[:3] + ["shapes/%s\tBAD" % first] + rows[3:7] + ["shapes/%s\tBAD" % later] + rows[7:]
        mf.write_text("\n".join(bad) + "\n")
        seen = set()
        for t in ("1", "2", "3", "8", "8", "8"):
            r = run("eval", mf, "--threads", t)
            assert r.returncode == 1 and r.stdout == "", (t, r.returncode, r.stderr)
            lines = r.stderr.splitlines()
            assert len(lines) == 1 and first in lines[0] and later not in lines[0], (t, r.stderr)
            seen.add(lines[0])
        assert len(seen) == 1, seen
        assert ("cannot use this shape" in seen.pop()) == (first == "line.txt")


def test_retrieval_joins_broken_pieces(tmp_path):
    """Retrieval commands trace images as `register` does: a large piece near the largest
    component (a limb broken off by a 2-pixel gap) is part of the shape. The broken shape then
    ranks nearer the whole one than the body alone, which it would equal if the piece were
    dropped (as `contour`, which traces the largest component only, shows)."""
    def draw(*rects):
        img = blank(110, 80)
        for x0, y0, x1, y1 in rects:
            fill_rect(img, x0, y0, x1, y1, 255)
        return img
    ext = img_ext()
    d = tmp_path / "set"
    d.mkdir()
    shapes = {"a_whole": draw((10, 20, 70, 50), (70, 28, 95, 42)),
              "b_broken": draw((10, 20, 70, 50), (72, 28, 95, 42)),
              "c_body": draw((10, 20, 70, 50))}
    for name, img in shapes.items():
        (d / (name + ext)).write_bytes(image_bytes(img, name + ext))
    r = run("matrix", d, "-o", "-", "--no-rerank")
    assert r.returncode == 0, r.stderr
    rows = [[float(v) for v in line.split("\t")] for line in r.stdout.splitlines() if not line.startswith("#")]
    broken = rows[1]
    assert broken[0] < broken[2], broken  # nearer the whole shape than the body alone
    body = run("contour", d / ("b_broken" + ext)).stdout
    assert body == run("contour", d / ("c_body" + ext)).stdout  # contour keeps the largest piece


def folder_of_points(d, names):
    """A folder of point lists, one affine copy of a base shape per name ("star-1.txt": star)."""
    d.mkdir(exist_ok=True)
    shapes = base_shapes()
    for k, name in enumerate(names):
        cls = [c for c in shapes if name.startswith(c)][0]
        write_points(d / name, affine(MAPS[k % len(MAPS)], shapes[cls]))
    return d


@pytest.mark.parametrize("kind", ["image", "points", "jpeg"])
def test_a_shape_given_as_the_collection(tmp_path, kind):
    """A single image or point list where a COLLECTION is expected says what it is, not that a
    manifest's header is missing."""
    q = tmp_path / "q.txt"
    write_points(q, base_shapes()["star"])
    coll = {"image": tmp_path / ("s" + img_ext()), "points": tmp_path / "p.txt", "jpeg": tmp_path / "a.jpg"}[kind]
    if kind == "image":
        coll.write_bytes(image_bytes(rasterize(base_shapes()["star"], 120, 120), coll.name))
    elif kind == "points":
        coll.write_text("# a shape\n" + q.read_text())
    else:
        coll.write_bytes(b"\xff\xd8\xff\xe0" + bytes(40))
    what = {"image": "a PNG or PGM image", "points": "a point list", "jpeg": "a JPEG image"}[kind]
    for args in (("search", q, coll), ("eval", coll), ("index", coll, "-o", tmp_path / "x.idx")):
        r = run(*args)
        assert r.returncode == 1 and r.stdout == "" and len(r.stderr.splitlines()) == 1, r.stderr
        assert "%s: %s, not a collection" % (coll, what) in r.stderr and "header" not in r.stderr, r.stderr
    assert not (tmp_path / "x.idx").exists()


def test_an_index_given_to_index_as_the_collection(tmp_path):
    d = folder_of_points(tmp_path / "set", ["star-1.txt", "blob-1.txt", "wave-1.txt"])
    idx = tmp_path / "s.idx"
    assert run("index", d, "-o", idx).returncode == 0
    r = run("index", idx, "-o", tmp_path / "t.idx")
    assert r.returncode == 1 and "an amscr index or collection file" in r.stderr, r.stderr


def test_a_folder_with_its_manifest_beside_the_shapes(tmp_path):
    """A folder whose shapes are in a subfolder beside its manifest.tsv: the error says to pass
    the manifest."""
    folder_of_points(tmp_path / "shapes", ["star-1.txt", "blob-1.txt"])
    (tmp_path / "manifest.tsv").write_text("file\tclass\nshapes/star-1.txt\tstar\nshapes/blob-1.txt\tblob\n")
    r = run("eval", tmp_path)
    assert r.returncode == 1 and len(r.stderr.splitlines()) == 1, r.stderr
    assert "no shapes in this folder" in r.stderr and "pass %s" % (tmp_path / "manifest.tsv") in r.stderr
    r = run("eval", tmp_path / "shapes")  # without a manifest: no hint
    assert r.returncode == 0, r.stderr


def test_manifest_with_a_byte_order_mark(tmp_path):
    """A UTF-8 byte order mark before the header (Excel's and Notepad's exports) is skipped."""
    folder_of_points(tmp_path / "shapes", ["star-1.txt", "star-2.txt", "blob-1.txt", "blob-2.txt"])
    rows = "file\tclass\r\n" + "".join("shapes/%s-%d.txt\t%s\r\n" % (c, k, c) for c in ("star", "blob")
                                         for k in (1, 2))
    plain, bom = tmp_path / "plain.tsv", tmp_path / "bom.tsv"
    plain.write_bytes(rows.encode())
    bom.write_bytes(b"\xef\xbb\xbf" + rows.encode())
    a, b = run("eval", plain, "--json", *AFFINE), run("eval", bom, "--json", *AFFINE)
    assert b.returncode == 0, b.stderr
    ja, jb = json.loads(a.stdout), json.loads(b.stdout)
    assert jb["n"] == 4 and jb["per_class"] == ja["per_class"]


def test_manifest_listing_a_file_twice(tmp_path):
    folder_of_points(tmp_path / "shapes", ["star-1.txt", "blob-1.txt", "blob-2.txt"])
    mf = tmp_path / "m.tsv"
    mf.write_text("file\tclass\nshapes/star-1.txt\tstar\nshapes/blob-1.txt\tblob\n# again\n"
                  "shapes/blob-2.txt\tblob\nshapes/star-1.txt\tstar\n")
    for args in (("eval", mf), ("index", mf, "-o", tmp_path / "x.idx")):
        r = run(*args)
        assert r.returncode == 1 and r.stdout == "" and len(r.stderr.splitlines()) == 1, r.stderr
        assert "m.tsv: line 6: 'shapes/star-1.txt' is already listed on line 2" in r.stderr, r.stderr
    assert not (tmp_path / "x.idx").exists()


def test_manifest_rows_of_the_headers_columns(tmp_path):
    """A row may leave the header's trailing columns out, but a row with more fields than the header
    names is an error naming the line (its extra field was ignored: a file name holding a tab, a
    row shifted by one)."""
    folder_of_points(tmp_path / "shapes", ["star-1.txt", "star-2.txt", "blob-1.txt", "blob-2.txt"])
    mf = tmp_path / "m.tsv"
    mf.write_text("file\tclass\tnote\nshapes/star-1.txt\tstar\tfirst\nshapes/star-2.txt\tstar\n"
                  "shapes/blob-1.txt\tblob\nshapes/blob-2.txt\tblob\n")
    r = run("eval", mf, "--json", *AFFINE)
    assert r.returncode == 0 and json.loads(r.stdout)["n"] == 4, r.stderr
    mf.write_text("file\tclass\nshapes/star-1.txt\tstar\nshapes/star-2.txt\tstar\tg1\n")
    r = run("eval", mf)
    assert r.returncode == 1 and r.stdout == "", r.stderr
    assert "m.tsv: line 3: expected at most 2 tab-separated columns (the header's), found 3" in r.stderr, r.stderr
    mf.write_text("file\tclass\tgroup\nshapes/star-1.txt\tstar\n")
    r = run("eval", mf)
    assert r.returncode == 1 and "line 2: expected at least 3 tab-separated columns" in r.stderr, r.stderr
    # at the reader's 64 columns too (a 65th field was kept, tabs and all, in the 64th)
    wide = "\t".join(["file", "class"] + ["c%d" % i for i in range(62)])
    rows = ["shapes/%s\t%s" % (f, f.split("-")[0]) for f in ["star-1.txt", "star-2.txt", "blob-1.txt", "blob-2.txt"]]
    mf.write_text(wide + "\n" + "\n".join(rows) + "\n")
    assert run("eval", mf, *AFFINE).returncode == 0
    mf.write_text(wide + "\n" + "\n".join(rows[:1] + [rows[1] + "\tx" * 63] + rows[2:]) + "\n")
    r = run("eval", mf)
    assert r.returncode == 1 and "m.tsv: line 3: 65 tab-separated columns, more than the 64" in r.stderr, r.stderr


def test_folder_warns_of_images_it_cannot_read(tmp_path):
    """Images of formats the tool does not read are skipped with one warning line naming how
    many and one of them; other files (notes, manifests) are skipped silently."""
    d = folder_of_points(tmp_path / "set", ["star-1.txt", "star-2.txt", "blob-1.txt", "blob-2.txt"])
    (d / "notes.md").write_text("# not a shape\n")
    (d / "list.tsv").write_text("file\tclass\n")
    r = run("eval", d, "--json", *AFFINE)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    (d / "b.jpg").write_bytes(b"\xff\xd8\xff\xe0" + bytes(40))
    (d / "a.tif").write_bytes(b"II*\x00" + bytes(40))
    (d / "c.bmp").write_bytes(b"BM" + struct.pack("<I", 46) + bytes(40))
    r = run("eval", d, "--json", *AFFINE)
    assert r.returncode == 0 and json.loads(r.stdout)["n"] == 4
    assert r.stderr == "amscr: %s: 3 files skipped: not PNG, PGM or a point list (e.g. a.tif)\n" % d, r.stderr
    (d / "a.tif").unlink()
    (d / "c.bmp").unlink()
    r = run("eval", d, *AFFINE)
    one = "amscr: %s: 1 file skipped: not PNG, PGM or a point list (e.g. b.jpg)\n" % d
    assert r.returncode == 0 and r.stderr == one, r.stderr
    (d / "b.jpg").unlink()  # named as images, and none: empty, text, a dangling link
    (d / "empty.png").write_bytes(b"")
    (d / "text.pgm").write_text("not an image\n")
    (d / "broken.png").symlink_to("nowhere.png")
    r = run("eval", d, "--json", *AFFINE)
    assert r.returncode == 0 and json.loads(r.stdout)["n"] == 4
    assert r.stderr == "amscr: %s: 3 files skipped: not PNG, PGM or a point list (e.g. broken.png)\n" % d, r.stderr


def test_folder_skips_text_files_that_are_no_point_lists(tmp_path):
    """A .txt or .csv of a folder whose first line is no point (a README.txt, a classes.csv, an
    empty notes.txt) is skipped with the warning line, as a .png that is no image: it does not make
    the whole folder fail. A point list with a bad line further on is still an error naming it."""
    d = folder_of_points(tmp_path / "set", ["star-1.txt", "star-2.txt", "blob-1.txt", "blob-2.txt"])
    (d / "README.txt").write_text("Shapes of stars and blobs.\n")
    (d / "classes.csv").write_text("class,files\nstar,star-1 star-2\n")
    (d / "notes.txt").write_bytes(b"")
    r = run("eval", d, "--json", *AFFINE)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["n"] == 4
    assert r.stderr == "amscr: %s: 3 files skipped: not PNG, PGM or a point list (e.g. README.txt)\n" % d, r.stderr
    (d / "star-3.txt").write_text("\ufeff# a comment, then a point\n\n 1 2\n3 x\n")
    r = run("matrix", d, "-o", "-", *AFFINE)
    assert r.returncode == 1 and r.stderr.endswith("star-3.txt:4: expected 2 numbers\n"), r.stderr
    # a point list that opens with a comment longer than any buffer is a point list
    (d / "star-3.txt").write_text("#" + "x" * 5000 + "\n" + (d / "star-1.txt").read_text())
    r = run("eval", d, "--json", *AFFINE)
    assert r.returncode == 0 and json.loads(r.stdout)["n"] == 5, r.stderr


def _as_nobody():
    """A preexec_fn that runs the tool as `nobody` when the tests run as root (whom no file
    mode stops), else None; pytest.skip when that cannot be done."""
    if os.geteuid() != 0:
        return None
    if not hasattr(os, "setresuid"):
        pytest.skip("running as root without setresuid: cannot make a file unreadable")
    return lambda: (os.setgroups([]), os.setresgid(65534, 65534, 65534), os.setresuid(65534, 65534, 65534))


def test_folder_shape_that_cannot_be_read_is_an_error(tmp_path):
    """A file named as a shape that cannot be opened (no permission) is an error naming it and
    why, whether it is named .png or .txt: it is not skipped as 'not PNG, PGM or a point list'."""
    import tempfile
    drop = _as_nobody()
    top = tempfile.mkdtemp(prefix="amscr-unreadable-")  # nobody must reach it (pytest's tmp is 0700)
    try:
        os.chmod(top, 0o755)
        d = folder_of_points(Path(top) / "set", ["star-1.txt", "star-2.txt", "blob-1.txt", "blob-2.txt"])
        os.chmod(d, 0o755)
        for f in d.iterdir():
            os.chmod(f, 0o644)
        if drop is not None:
            probe = subprocess.run([tool_path(), "--version"], capture_output=True, preexec_fn=drop)
            if probe.returncode != 0:
                pytest.skip("the tool cannot run as nobody here: %s" % probe.stderr.decode(errors="replace"))
        for name in ("blob-3.png", "blob-3.txt"):
            if name.endswith(".png"):
                (d / name).write_bytes(image_bytes(rasterize([(10, 10), (60, 12), (40, 50)], 80, 80), "x.png"))
            else:
                write_points(d / name, base_shapes()["blob"])
            os.chmod(d / name, 0)
            r = subprocess.run([tool_path(), "matrix", str(d), "-o", "-", *AFFINE], capture_output=True,
                               text=True, preexec_fn=drop)
            assert r.returncode == 1, r.stderr
            assert "%s: cannot open: Permission denied" % (d / name) in r.stderr, r.stderr
            assert "skipped" not in r.stderr, r.stderr
            os.unlink(d / name)
    finally:
        subprocess.run(["rm", "-rf", top])


def test_class_names_drop_trailing_separators(tmp_path):
    """'star 3.txt' is of class star, as star-1.txt is; the other names keep their classes."""
    d = folder_of_points(tmp_path / "set", ["star-1.txt", "star 3.txt", "star - 4.txt", "blob01.txt",
                                           "blob_2.txt", "wave.txt", "wave-.txt"])
    names = tmp_path / "names.tsv"
    r = run("matrix", d, "-o", tmp_path / "d.tsv", "--names", names, *AFFINE)
    assert r.returncode == 0, r.stderr
    classes = dict(line.split("\t") for line in names.read_text().splitlines()[1:])  # after the header
    assert classes == {"star-1.txt": "star", "star 3.txt": "star", "star - 4.txt": "star", "blob01.txt": "blob",
                       "blob_2.txt": "blob", "wave.txt": "wave", "wave-.txt": "wave-"}


def test_no_output_overwrites_a_file_the_command_reads(tmp_path):
    """search --sheet, matrix -o / --names and index -o refuse a file the command reads (the
    query, the manifest, a shape of the folder or the manifest), leaving it as it was; an index
    is not read shape by shape, and index --add rewrites its own FILE."""
    d = folder_of_points(tmp_path / "set", ["star-1.txt", "star-2.txt", "blob-1.txt", "blob-2.txt"])
    pic = d / ("star-3" + img_ext())
    pic.write_bytes(image_bytes(rasterize(base_shapes()["star"], 120, 120), pic.name))
    mf = tmp_path / "m.tsv"
    mf.write_text("file\tclass\n" + "".join("set/%s\t%s\n" % (f, f.split("-")[0]) for f in
                                            ("star-1.txt", "star-2.txt", "blob-1.txt", "blob-2.txt", pic.name)))
    q, member = d / "star-1.txt", d / "blob-2.txt"
    before = {f: f.read_bytes() for f in (q, member, mf, pic)}
    for args in (("search", pic, d, "--sheet", pic), ("search", q, mf, "--sheet", tmp_path / "set" / "." / pic.name),
                 ("matrix", mf, "-o", mf), ("matrix", d, "-o", member),
                 ("matrix", d, "-o", tmp_path / "x.tsv", "--names", member),
                 ("matrix", d, "-o", tmp_path / "y.tsv", "--names", tmp_path / "y.tsv"),
                 ("index", d, "-o", member), ("index", mf, "-o", mf)):
        r = run(*args, *AFFINE)
        assert r.returncode == 1 and r.stdout == "" and len(r.stderr.splitlines()) == 1, (args, r.stderr)
        assert "would overwrite an input" in r.stderr or "name the same file" in r.stderr, (args, r.stderr)
    assert {f: f.read_bytes() for f in before} == before
    assert not (tmp_path / "x.tsv").exists() and not (tmp_path / "y.tsv").exists()
    idx = tmp_path / "s.idx"
    assert run("index", mf, "-o", idx, *AFFINE).returncode == 0
    r = run("index", d, "-o", idx, "--add", *AFFINE)  # --add: FILE is the index itself (here a repeat)
    assert "would overwrite" not in r.stderr, r.stderr
    assert run("search", q, idx, "--sheet", tmp_path / "sheet.svg").returncode == 0


def test_outputs_through_links_fifos_and_devices(tmp_path):
    """An output that is a symbolic link replaces the file it points to (its mode kept), a FIFO is
    written through and stays a FIFO, /dev/stdout appends to what stdout is; a replaced file keeps
    its mode."""
    import stat
    import threading
    d = folder_of_points(tmp_path / "set", ["star-1.txt", "star-2.txt", "blob-1.txt", "blob-2.txt"])
    ref = tmp_path / "ref.tsv"
    assert run("matrix", d, "-o", ref, *AFFINE).returncode == 0
    want = ref.read_text()
    target, link = tmp_path / "target.tsv", tmp_path / "link.tsv"
    target.write_text("old\n")
    target.chmod(0o600)
    link.symlink_to("target.tsv")
    assert run("matrix", d, "-o", link, *AFFINE).returncode == 0
    assert link.is_symlink() and target.read_text() == want
    assert stat.S_IMODE(target.stat().st_mode) == 0o600
    assert run("matrix", d, "-o", target, *AFFINE).returncode == 0  # a replaced file keeps its mode
    assert stat.S_IMODE(target.stat().st_mode) == 0o600
    fifo = tmp_path / "fifo.tsv"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(open(fifo).read()))
    reader.start()
    r = run("matrix", d, "-o", fifo, *AFFINE, timeout=60)
    reader.join(30)
    assert r.returncode == 0, r.stderr
    assert got == [want] and stat.S_ISFIFO(os.lstat(fifo).st_mode)
    pts, log = tmp_path / "pts.txt", tmp_path / "log.txt"
    log.write_text("# before\n")
    with open(log, "a") as out:  # the shell's >>
        r = subprocess.run([tool_path(), "contour", str(d / "star-1.txt"), "-o", "/dev/stdout"], stdout=out)
    assert r.returncode == 0
    assert run("contour", d / "star-1.txt", "-o", pts).returncode == 0
    assert log.read_text() == "# before\n" + pts.read_text()


def test_lost_standard_output_is_an_error(tmp_path):
    """Output lost on stdout (a full disk, a closed stdout) is an error line and exit status 1,
    also past the stdio buffer."""
    d = folder_of_points(tmp_path / "set", ["star-%d.txt" % i for i in range(1, 9)])
    with open("/dev/full", "w") as full:
        r = subprocess.run([tool_path(), "register", str(d / "star-1.txt"), str(d / "star-2.txt"), "--json"],
                           stdout=full, stderr=subprocess.PIPE, text=True)
    assert r.returncode == 1 and "write error" in r.stderr, r.stderr
    r = subprocess.run([tool_path(), "search", str(d / "star-1.txt"), str(d), "--top", "8", *AFFINE],
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, close_fds=True,
                       pass_fds=(), preexec_fn=lambda: os.close(1))
    assert r.returncode == 1 and "write error" in r.stderr, r.stderr


def test_file_size_limit_is_an_error_line(tmp_path):
    """Over the file-size limit (ulimit -f) a write is an error with its line and exit status 1, the
    old file kept and no temporary left (SIGXFSZ killed the tool without a word)."""
    import resource
    d = folder_of_points(tmp_path / "set", ["star-%d.txt" % i for i in range(1, 9)])
    limit = lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (64, 64))  # noqa: E731 - bytes
    for cmd, name in (("matrix", "m.tsv"), ("index", "x.idx")):  # the tool's writer, the library's
        out = tmp_path / name
        out.write_text("old\n")
        r = subprocess.run([tool_path(), cmd, str(d), "-o", str(out), *AFFINE], capture_output=True, text=True,
                           preexec_fn=limit)
        assert r.returncode == 1 and name in r.stderr and "File too large" in r.stderr, (r.returncode, r.stderr)
        assert out.read_text() == "old\n"
    assert sorted(os.listdir(tmp_path)) == ["m.tsv", "set", "x.idx"]


def test_shapes_through_a_pipe_read_whole(tmp_path):
    """A point list or an image given through a pipe (/dev/stdin) is read whole, as the file gives
    it (its first bytes were lost to the format's sniffing); a collection through a pipe is
    refused with its reason."""
    d = folder_of_points(tmp_path / "set", ["star-1.txt", "star-2.txt", "blob-1.txt", "blob-2.txt"])
    src, tgt = d / "star-1.txt", d / "star-2.txt"
    pic = tmp_path / ("star" + img_ext())
    pic.write_bytes(image_bytes(rasterize(base_shapes()["star"], 120, 120), pic.name))
    for f in (src, pic):
        want = run("register", f, tgt, "--json")
        assert want.returncode == 0, want.stderr
        r = subprocess.run([tool_path(), "register", "/dev/stdin", str(tgt), "--json"], input=f.read_bytes(),
                           capture_output=True)
        got = json.loads(r.stdout)
        for key in ("source_points", "distance", "A", "B"):
            assert got[key] == json.loads(want.stdout)[key], (f, key)
    r = subprocess.run([tool_path(), "eval", "/dev/stdin"], input="file\tclass\nstar-1.txt\tstar\n",
                       capture_output=True, text=True)  # a manifest through a pipe: its shapes need a folder
    assert r.returncode == 1 and "a pipe or a device" in r.stderr, r.stderr


def test_matrix_to_a_device_and_names_a_tsv_cannot_hold(tmp_path):
    """matrix -o /dev/stdout writes the TSV; a file name holding a tab or a line break is refused
    with --names (a names file is TSV) before any shape is prepared, and allowed without it."""
    d = folder_of_points(tmp_path / "set", ["star-1.txt", "star-2.txt", "blob-1.txt", "blob\t2.txt"])
    r = run("matrix", d, "-o", "/dev/stdout", *AFFINE)
    assert r.returncode == 0 and len(r.stdout.splitlines()) == 5, r.stderr
    r = run("matrix", d, "-o", tmp_path / "d.tsv", "--names", tmp_path / "n.tsv", *AFFINE)
    assert r.returncode == 1 and "tab or a line break" in r.stderr, r.stderr
    assert not (tmp_path / "d.tsv").exists() and not (tmp_path / "n.tsv").exists()


def test_outputs_named_together_or_not_at_all(tmp_path):
    """register --overlay/--plot and matrix -o/--names: when one output cannot be written (here a
    link to /dev/full), the other is not left written either; an output that cannot be made fails
    before any shape is prepared."""
    d = folder_of_points(tmp_path / "set", ["star-1.txt", "star-2.txt", "blob-1.txt", "blob-2.txt"])
    full = tmp_path / "full.svg"
    full.symlink_to("/dev/full")
    r = run("register", d / "star-1.txt", d / "star-2.txt", "--overlay", tmp_path / "o.svg", "--plot", full)
    assert r.returncode == 1 and "No space left" in r.stderr, r.stderr
    assert not (tmp_path / "o.svg").exists()
    r = run("matrix", d, "-o", tmp_path / "m.tsv", "--names", full, *AFFINE)
    assert r.returncode == 1 and not (tmp_path / "m.tsv").exists(), r.stderr
    assert sorted(os.listdir(tmp_path)) == ["full.svg", "set"]
    r = run("index", d, "-o", tmp_path / "no" / "x.idx", *AFFINE)  # before the work
    assert r.returncode == 1 and "no/x.idx" in r.stderr and "index" not in r.stdout, r.stderr
