#!/usr/bin/env python3
"""Lists the AMSCR_API function names declared in include/amscr.h.

  gen_map.py names            one name a line
  gen_map.py check MAPFILE    exits 1 when the map's global names differ from the header's
"""
import os
import re
import sys

here = os.path.dirname(os.path.abspath(__file__))
HEADER = os.path.join(here, '..', 'include', 'amscr.h')


def header_names(path=HEADER):
    text = open(path, encoding='utf-8').read()
    text = re.sub(r'/\*.*?\*/', ' ', text, flags=re.S)
    names = []
    for decl in re.findall(r'AMSCR_API\b([^;]*);', text):
        m = re.search(r'(\w+)\s*\(', decl.replace('AMSCR_NODISCARD', ''))
        if m and m.group(1) not in ('visibility', '__declspec'):
            names.append(m.group(1))
    return names


def map_names(path):
    text = open(path, encoding='utf-8').read()
    text = re.sub(r'#[^\n]*', '', text)
    names = []
    for block in re.findall(r'global:(.*?)(?:local:|\})', text, flags=re.S):
        names += [n.strip() for n in block.split(';') if n.strip()]
    return names


if __name__ == '__main__':
    if len(sys.argv) >= 2 and sys.argv[1] == 'check':
        h, m = set(header_names()), set(map_names(sys.argv[2]))
        if h != m:
            print('in header, not in map:', sorted(h - m))
            print('in map, not in header:', sorted(m - h))
            sys.exit(1)
        print('map and header agree: %d symbols' % len(h))
    else:
        print('\n'.join(header_names()))
