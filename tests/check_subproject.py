#!/usr/bin/env python3
"""amscr as another project's Meson subproject: `dependency('amscr')` falls back to it (the
library's meson.override_dependency), and the other project's build gets the library and the tool,
not amscr's tests, tool and Python suites or benchmarks (nor their targets in its `meson test`).

    check_subproject.py MESON SOURCE_ROOT

Configures (does not build) a one-file consumer in a temporary folder whose subprojects/amscr is
a link to SOURCE_ROOT, with --wrap-mode=forcefallback (an installed amscr.pc is not used).
"""
import json
import os
import subprocess
import sys
import tempfile

CONSUMER = """project('consumer', 'c', default_options: ['c_std=c99'])
dep = dependency('amscr', fallback: 'amscr')  # no variable name: the subproject's override
executable('consumer', 'consumer.c', dependencies: dep)
"""
SOURCE = '#include <amscr.h>\nint main(void) { return amscr_version_number() > 0 ? 0 : 1; }\n'


def main():
    meson, source_root = sys.argv[1], os.path.realpath(sys.argv[2])
    with tempfile.TemporaryDirectory(prefix='amscr-subproject-') as tmp:
        with open(os.path.join(tmp, 'meson.build'), 'w') as f:
            f.write(CONSUMER)
        with open(os.path.join(tmp, 'consumer.c'), 'w') as f:
            f.write(SOURCE)
        os.makedirs(os.path.join(tmp, 'subprojects'))
        os.symlink(source_root, os.path.join(tmp, 'subprojects', 'amscr'))
        build = os.path.join(tmp, 'b')
        r = subprocess.run([meson, 'setup', '--wrap-mode=forcefallback', build, tmp],
                           capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit('meson setup of the consumer failed:\n' + r.stdout + r.stderr)

        def introspect(what):
            out = subprocess.run([meson, 'introspect', what, build], capture_output=True, text=True, check=True)
            return json.loads(out.stdout)
        targets = introspect('--targets')
        names = {t['name'] for t in targets}
        assert 'consumer' in names and 'amscr' in names, sorted(names)
        sub = os.path.join(tmp, 'subprojects', 'amscr')
        stray = sorted(t['name'] for t in targets
                       if os.path.relpath(t['defined_in'], sub).split(os.sep)[0] in ('tests', 'bench', 'bindings'))
        assert not stray, 'the consumer builds amscr\'s test and benchmark targets: %s' % ', '.join(stray[:8])
        stray = sorted(t['name'] for t in targets if t['build_by_default'] and t['name'] == 'amscr_internal')
        assert not stray, 'the consumer builds amscr\'s white-box static library'
        tests = introspect('--tests')
        assert not tests, 'amscr\'s suites are in the consumer\'s meson test: %s' % ', '.join(
            sorted(t['name'] for t in tests)[:8])
    print('amscr as a subproject: the library and the tool only, no test or benchmark targets, no tests')


if __name__ == '__main__':
    main()
