#!/usr/bin/env python3
"""Exported symbols of libamscr.so == global names of src/amscr.map == AMSCR_API names in
include/amscr.h, and nothing exported lacks the amscr_ prefix."""
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'scripts'))
import gen_map  # noqa: E402

lib, mapfile = sys.argv[1], sys.argv[2]
out = subprocess.run(['nm', '-D', '--defined-only', lib], check=True, capture_output=True, text=True).stdout
exported = set()
for line in out.splitlines():
    parts = line.split()
    if len(parts) >= 3 and parts[1] in 'TDBRW':
        name = parts[2].split('@')[0]
        exported.add(name)
exported.discard('AMSCR_0.1')
bad = sorted(n for n in exported if not n.startswith('amscr_'))
mapped = set(gen_map.map_names(mapfile))
declared = set(gen_map.header_names())
ok = True
if bad:
    print('exported without the amscr_ prefix:', bad)
    ok = False
if exported != mapped:
    print('exported but not in map:', sorted(exported - mapped))
    print('in map but not exported:', sorted(mapped - exported))
    ok = False
if declared != mapped:
    print('declared but not in map:', sorted(declared - mapped))
    print('in map but not declared:', sorted(mapped - declared))
    ok = False
print('%d symbols exported, map and header agree' % len(exported) if ok else 'symbol check FAILED')
sys.exit(0 if ok else 1)
