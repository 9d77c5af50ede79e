#!/usr/bin/env python3
"""The "Constants chosen on data" table of docs/decisions.md against the source.

Every code span `NAME = VALUE` in the first cell (the value) of that table's rows names a
constant of src/: a macro (`#define NAME EXPR`, every definition) or, when no macro has the
name, an assignment (`NAME = EXPR;`, at least one). EXPR and VALUE are evaluated as arithmetic (other macros expanded,
sqrt(x) allowed) and must agree to 1e-9. A constant renamed, removed or changed without its row
fails here; so does a table whose rows name no constant at all.

Usage: check_constants.py DECISIONS_MD SRC_DIR
"""
import math
import os
import re
import sys

SPAN = re.compile(r'`([A-Za-z_][A-Za-z0-9_]*)\s*=\s*([^`]+)`')
DEFINE = re.compile(r'^\s*#\s*define\s+([A-Za-z_][A-Za-z0-9_]*)[ \t]+(.+?)\s*(?:/\*.*)?$', re.M)


def table_rows(md):
    """The rows of the table under the '## Constants chosen on data' heading."""
    lines = md.split('\n')
    start = next(i for i, l in enumerate(lines) if l.strip() == '## Constants chosen on data')
    rows = []
    for l in lines[start + 1:]:
        if l.startswith('## '):
            break
        if l.startswith('|') and not l.startswith('|---'):
            rows.append(l)
    return rows[1:]  # without the header


def value(expr, macros, depth=0):
    if depth > 10:
        raise ValueError('macro recursion in %r' % expr)
    expr = expr.replace('√', 'sqrt').strip()
    expr = re.sub(r'\((?:double|int|size_t|float)\)', '', expr)
    expr = re.sub(r'(?<=[0-9.])[uUlLfF]+\b', '', expr)

    def sub(m):
        name = m.group(0)
        if name == 'sqrt':
            return name
        if name not in macros:
            raise ValueError('unknown name %s in %r' % (name, expr))
        return '(%r)' % value(macros[name][0], macros, depth + 1)
    py = re.sub(r'[A-Za-z_][A-Za-z0-9_]*', sub, expr)
    if not re.fullmatch(r'[0-9eE.+\-*/() sqrt]*', py):
        raise ValueError('not arithmetic: %r' % expr)
    return float(eval(py, {'__builtins__': {}}, {'sqrt': math.sqrt}))  # noqa: S307 (checked above)


def main(md_path, src):
    texts = {}
    for d, _, files in os.walk(src):
        for f in files:
            if f.endswith(('.c', '.h')):
                p = os.path.join(d, f)
                texts[p] = open(p, encoding='utf-8').read()
    macros = {}
    for p, t in texts.items():
        for m in DEFINE.finditer(t):
            macros.setdefault(m.group(1), []).append(m.group(2))
    rows = table_rows(open(md_path, encoding='utf-8').read())
    bad, n = [], 0
    for row in rows:
        for name, want in SPAN.findall(row.split('|')[1]):
            n += 1
            try:
                w = value(want, macros)
                if name in macros:
                    got = [value(e, macros) for e in macros[name]]
                    if any(not math.isclose(g, w, rel_tol=1e-9, abs_tol=1e-300) for g in got):
                        bad.append('%s: the table says %s, the source %s' % (name, want, ' / '.join(macros[name])))
                    continue
                pat = re.compile(r'(?<![A-Za-z0-9_])' + re.escape(name) + r'\s*=\s*([^;=][^;]*);')
                got = [m.group(1) for t in texts.values() for m in pat.finditer(t)]
                vals = []
                for g in got:  # an assignment from a variable (a.x = b->x) is not the constant
                    try:
                        vals.append(value(g, macros))
                    except ValueError:
                        pass
                if not vals:
                    bad.append('%s: no constant assignment in %s' % (name, src))
                elif not any(math.isclose(v, w, rel_tol=1e-9) for v in vals):
                    bad.append('%s: the table says %s, the source %s' % (name, want, ' / '.join(got)))
            except ValueError as e:
                bad.append('%s: %s' % (name, e))
    if n == 0:
        bad.append('no `NAME = VALUE` constant in the table of %s' % md_path)
    for b in bad:
        print('FAIL ' + b)
    print('%d constants checked, %d wrong' % (n, len(bad)))
    return 1 if bad else 0


if __name__ == '__main__':
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2]))
