"""Runs the README's C example (tests/readme_example.c) on the bundled exact polygon pair and
checks the map it prints: the true map of examples/README.md, A = [[0.75, 0.35], [-0.2, 0.65]],
B = [-15.7, 46.6], to the printed digits, and a distance of ~0 (measured 7.31e-15).
Usage: check_readme_example.py EXAMPLE SRC.txt TGT.txt"""
import re
import subprocess
import sys

A_TRUE = [0.75, 0.35, -0.2, 0.65]
B_TRUE = [-15.7, 46.6]


def main():
    out = subprocess.run(sys.argv[1:4], capture_output=True, text=True, timeout=120)
    if out.returncode != 0:
        sys.exit("readme_example failed (%d): %s" % (out.returncode, out.stderr))
    num = r"(-?[0-9.]+(?:e[-+]?[0-9]+)?)"
    m = re.fullmatch(r"A = \[\[{0}, {0}\], \[{0}, {0}\]\]  B = \[{0}, {0}\]  distance = {0}\n".format(num), out.stdout)
    if not m:
        sys.exit("unexpected output: %r" % out.stdout)
    v = [float(x) for x in m.groups()]
    errors = []
    if any(abs(a - t) > 1e-4 for a, t in zip(v[:4], A_TRUE)):  # printed with 4 decimals
        errors.append("A = %s, expected %s" % (v[:4], A_TRUE))
    if any(abs(b - t) > 1e-3 for b, t in zip(v[4:6], B_TRUE)):  # printed with 3 decimals
        errors.append("B = %s, expected %s" % (v[4:6], B_TRUE))
    if not 0 <= v[6] < 1e-13:
        errors.append("distance %g, expected < 1e-13" % v[6])
    if errors:
        sys.exit("; ".join(errors))
    print(out.stdout, end="")


if __name__ == "__main__":
    main()
