#!/usr/bin/env python3
"""Every `@param` of include/amscr.h names exactly one parameter of the declaration its comment
documents, as Doxygen and clang's -Wdocumentation read it: a consumer compiling with
-Wdocumentation (or -Weverything) sees no warning from the header. The rule clang applies
without clang: `@param a, b` is a parameter named "a," and warns."""
import re
import sys

COMMENT = re.compile(r'/\*\*(.*?)\*/\s*(AMSCR_API[^;{]*?\b(amscr_\w+)\s*\((.*?)\)\s*;)', re.S)
PARAM = re.compile(r'@param(?:\[[a-z,]+\])?\s+(\S+)')


def parameter_names(arglist):
    """The names in a C parameter list: the last identifier of each argument, arrays aside."""
    names = []
    for arg in arglist.split(','):
        arg = re.sub(r'\[[^\]]*\]', '', arg).strip()
        if arg in ('void', ''):
            continue
        names.append(re.findall(r'[A-Za-z_]\w*', arg)[-1])
    return names


def problems(header):
    text = open(header, encoding='utf-8').read()
    found, count = [], 0
    for m in COMMENT.finditer(text):
        doc, name, args = m.group(1), m.group(3), m.group(4)
        if '/**' in doc:  # the comment matched runs across another: only the last one documents
            doc = doc.rsplit('/**', 1)[1]
        have = set(parameter_names(args))
        for p in PARAM.findall(doc):
            count += 1
            if p not in have:
                line = text.count('\n', 0, m.start()) + 1
                found.append('%s:%d: %s: @param %r is not one of its parameters %s'
                             % (header, line, name, p, sorted(have)))
    return found, count


def main():
    found, count = problems(sys.argv[1])
    for f in found:
        print(f)
    if count < 100:
        print('only %d @param lines read: the header parser is broken' % count)
        return 1
    print('%d @param lines, %d not naming one parameter' % (count, len(found)))
    return 1 if found else 0


if __name__ == '__main__':
    sys.exit(main())
