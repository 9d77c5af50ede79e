#!/usr/bin/env python3
"""Generates the cffi declarations bindings/python/amscr/_cdef.h from include/amscr.h.

STYLE.md rule 30: the Python view of the ABI is derived from the one public header, and a test
(bindings/python/tests/test_packaging.py) fails when the committed copy differs from what this
script prints. The filter (no C preprocessor needed, so the output does not depend on the
system's headers):

* comments are removed, backslash-continued lines joined;
* every preprocessor line is dropped, except ``#define NAME <integer expression>``, which becomes
  ``#define NAME <decimal value>`` (cffi accepts plain integer macros in both modes; in API mode
  the compiler checks the value against the real header at build time);
* ``AMSCR_API`` and ``AMSCR_NODISCARD`` are removed, and so are the ``extern "C" {`` guard and
  its closing brace;
* every enumerator gets an explicit value (ABI mode cannot ask a compiler);
* each declaration is printed on one line (enum bodies one enumerator per line), so the file is
  stable under any re-wrapping of the header.

Usage:
    scripts/gen_cdef.py [HEADER] [-o OUT]     write OUT (default: stdout)
    scripts/gen_cdef.py --check [HEADER]      exit 1 when the committed copy is stale
"""
import argparse
import ast
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, '..'))
DEFAULT_HEADER = os.path.join(ROOT, 'include', 'amscr.h')
DEFAULT_OUT = os.path.join(ROOT, 'bindings', 'python', 'amscr', '_cdef.h')

STRIP_TOKENS = ('AMSCR_API', 'AMSCR_NODISCARD')


class CdefError(Exception):
    pass


def _strip_comments(text):
    """Removes /* */ and // comments, keeping string and char literals intact."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith('/*', i):
            j = text.find('*/', i + 2)
            if j < 0:
                raise CdefError('unterminated comment')
            # keep line structure (a comment may separate two tokens)
            out.append(' ' + '\n' * text.count('\n', i, j))
            i = j + 2
        elif text.startswith('//', i):
            j = text.find('\n', i)
            i = n if j < 0 else j
        elif c in '"\'':
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == '\\' else 1
            out.append(text[i:j + 1])
            i = j + 1
        else:
            out.append(c)
            i += 1
    return ''.join(out)


_INT_LITERAL = re.compile(r'\b(0[xX][0-9a-fA-F]+|\d+)[uUlL]*\b')


def _eval_int(expr, known):
    """Evaluates an integer constant expression of literals, known macros, + - * / % << >> | & ( )."""
    expr = _INT_LITERAL.sub(lambda m: str(int(m.group(1), 0)), expr)
    tree = ast.parse(expr.strip(), mode='eval')

    def ev(node):
        if isinstance(node, ast.Expression):
            return ev(node.body)
        if isinstance(node, ast.Constant) and isinstance(node.value, int):
            return node.value
        if isinstance(node, ast.Name):
            if node.id not in known:
                raise CdefError('unknown name %s' % node.id)
            return known[node.id]
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd, ast.Invert)):
            v = ev(node.operand)
            return -v if isinstance(node.op, ast.USub) else (~v if isinstance(node.op, ast.Invert) else v)
        if isinstance(node, ast.BinOp):
            a, b = ev(node.left), ev(node.right)
            ops = {ast.Add: lambda: a + b, ast.Sub: lambda: a - b, ast.Mult: lambda: a * b,
                   ast.Div: lambda: int(a / b), ast.FloorDiv: lambda: a // b, ast.Mod: lambda: a % b,
                   ast.LShift: lambda: a << b, ast.RShift: lambda: a >> b,
                   ast.BitOr: lambda: a | b, ast.BitAnd: lambda: a & b, ast.BitXor: lambda: a ^ b}
            for k, f in ops.items():
                if isinstance(node.op, k):
                    return f()
        raise CdefError('not an integer constant expression: %r' % expr)

    return ev(tree)


def _split_top_level(body, sep):
    parts, depth, cur = [], 0, []
    for ch in body:
        if ch in '({[':
            depth += 1
        elif ch in ')}]':
            depth -= 1
        if ch == sep and depth == 0:
            parts.append(''.join(cur))
            cur = []
        else:
            cur.append(ch)
    parts.append(''.join(cur))
    return parts


def _norm(s):
    s = re.sub(r'\s+', ' ', s).strip()
    s = re.sub(r'\s*([(),;\[\]])\s*', r'\1', s)
    s = s.replace(',', ', ')
    s = re.sub(r'\*\s+', '*', s)
    s = re.sub(r'(\w)\(\*', r'\1 (*', s)
    return s


def _format_enum(decl, known):
    m = re.match(r'^typedef enum(\s+\w+)?\s*\{(.*)\}\s*(\w+)\s*;$', decl, re.S)
    if not m:
        m2 = re.match(r'^enum\s+(\w+)\s*\{(.*)\}\s*;$', decl, re.S)
        if not m2:
            raise CdefError('unsupported enum declaration: %s' % decl[:80])
        head, body, tail = 'enum %s {' % m2.group(1), m2.group(2), '};'
    else:
        tag = m.group(1).strip() if m.group(1) else None
        head = 'typedef enum %s{' % (tag + ' ' if tag else '')
        body, tail = m.group(2), '} %s;' % m.group(3)
    lines, value = [head], -1
    items = [it.strip() for it in _split_top_level(body, ',') if it.strip()]
    for k, item in enumerate(items):
        if '=' in item:
            name, expr = (x.strip() for x in item.split('=', 1))
            value = _eval_int(expr, known)
        else:
            name = item
            value += 1
        if not re.match(r'^[A-Za-z_]\w*$', name):
            raise CdefError('bad enumerator %r' % name)
        known[name] = value
        lines.append('    %s = %d%s' % (name, value, ',' if k + 1 < len(items) else ''))
    lines.append(tail)
    return '\n'.join(lines)


def generate(header_text, header_name='include/amscr.h'):
    text = _strip_comments(header_text.replace('\r\n', '\n'))
    text = re.sub(r'\\\n', ' ', text)
    defines, body_lines, known = [], [], {}
    for line in text.split('\n'):
        s = line.strip()
        if s.startswith('#'):
            m = re.match(r'^#\s*define\s+([A-Za-z_]\w*)\s+(.+)$', s)
            if m and m.group(1) not in STRIP_TOKENS and not m.group(1).endswith('_H'):
                try:
                    v = _eval_int(m.group(2), known)
                except (CdefError, SyntaxError):
                    continue  # not an integer constant (attributes, strings, ...)
                known[m.group(1)] = v
                defines.append('#define %s %d' % (m.group(1), v))
            continue
        body_lines.append(line)
    body = '\n'.join(body_lines)
    body = re.sub(r'extern\s+"C"\s*\{', '', body)
    for tok in STRIP_TOKENS:
        body = re.sub(r'\b%s\b' % tok, ' ', body)
    # Split into top-level declarations; drop the stray '}' closing the extern "C" block.
    decls, depth, cur = [], 0, []
    for ch in body:
        if ch == '{':
            depth += 1
        elif ch == '}':
            if depth == 0:
                continue  # the extern "C" closing brace
            depth -= 1
        cur.append(ch)
        if ch == ';' and depth == 0:
            decls.append(''.join(cur).strip())
            cur = []
    rest = ''.join(cur).strip()
    if rest:
        raise CdefError('trailing text that is not a declaration: %r' % rest[:80])

    out = ['/* Generated by scripts/gen_cdef.py from %s: do not edit. */' % header_name,
           '/* Regenerate with: python3 scripts/gen_cdef.py -o bindings/python/amscr/_cdef.h */', '']
    out += defines
    out.append('')
    for d in decls:
        d = re.sub(r'\s+', ' ', d).strip()
        if 'enum' in d.split('{')[0] and '{' in d:
            out.append(_format_enum(d, known))
        elif '{' in d:
            raise CdefError('struct bodies are not allowed in the public header: %s' % d[:80])
        elif '...' in d:
            raise CdefError('varargs are not allowed in the public header: %s' % d[:80])
        else:
            out.append(_norm(d))
    return '\n'.join(out) + '\n'


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('header', nargs='?', default=DEFAULT_HEADER)
    ap.add_argument('-o', '--output', help='write here instead of stdout')
    ap.add_argument('--check', action='store_true', help='compare with the committed %s' % DEFAULT_OUT)
    args = ap.parse_args(argv)
    with open(args.header, encoding='utf-8') as f:
        text = generate(f.read())
    if args.check:
        try:
            with open(args.output or DEFAULT_OUT, encoding='utf-8') as f:
                committed = f.read()
        except OSError:
            committed = None
        if committed != text:
            sys.stderr.write('%s is stale: run python3 scripts/gen_cdef.py -o %s\n'
                             % (args.output or DEFAULT_OUT, os.path.relpath(DEFAULT_OUT, ROOT)))
            return 1
        return 0
    if args.output:
        tmp = args.output + '.tmp'
        with open(tmp, 'w', encoding='utf-8', newline='\n') as f:
            f.write(text)
        os.replace(tmp, args.output)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == '__main__':
    sys.exit(main())
