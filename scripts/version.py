#!/usr/bin/env python3
"""Prints the version "M.m.p" read from include/amscr.h (the one source of truth)."""
import os
import re
import sys

here = os.path.dirname(os.path.abspath(__file__))
header = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, '..', 'include', 'amscr.h')
text = open(header, encoding='utf-8').read()
parts = [re.search(r'#define AMSCR_VERSION_%s (\d+)' % k, text).group(1) for k in ('MAJOR', 'MINOR', 'PATCH')]
print('.'.join(parts))
