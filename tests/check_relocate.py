#!/usr/bin/env python3
"""The installed `amscr` tool runs from a prefix moved after the install (here: staged with DESTDIR,
the prefix itself never created) and loads the library installed beside it, not another one.

    check_relocate.py MESON BUILD_ROOT

Installs the build's run-time files (the tool and the shared library: `--tags runtime`) with
DESTDIR into a temporary folder and runs the staged tool with no LD_LIBRARY_PATH. A build for the
prefix /usr (whose tool has no run path: the system's folders) is skipped, exit status 77.
"""
import json
import os
import subprocess
import sys
import tempfile


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        sys.exit('%s failed:\n%s%s' % (' '.join(cmd), r.stdout, r.stderr))
    return r.stdout


def main():
    meson, build = sys.argv[1], os.path.realpath(sys.argv[2])
    options = {o['name']: o['value'] for o in json.loads(run([meson, 'introspect', '--buildoptions', build]))}
    prefix, bindir = options['prefix'], options['bindir']
    if prefix == '/usr' or os.path.isabs(bindir):
        print('SKIP: a build for %s (bindir %s) has no relative run path to check' % (prefix, bindir))
        sys.exit(77)
    with tempfile.TemporaryDirectory(prefix='amscr-relocate-') as stage:
        run([meson, 'install', '-C', build, '--no-rebuild', '--quiet', '--tags', 'runtime', '--destdir', stage])
        staged = stage + prefix
        tool = os.path.join(staged, bindir, 'amscr')
        env = {k: v for k, v in os.environ.items() if k != 'LD_LIBRARY_PATH'}
        r = subprocess.run([tool, '--version'], capture_output=True, text=True, env=env)
        assert r.returncode == 0, 'the staged tool does not start: %s' % r.stderr.strip()
        ldd = run(['ldd', tool], env=env)
        line = next(l for l in ldd.splitlines() if 'libamscr.so' in l)
        assert os.path.realpath(line.split('=>')[1].split('(')[0].strip()).startswith(os.path.realpath(staged)), \
            'the staged tool loads another libamscr: %s' % line.strip()
    print('the installed tool runs from a moved prefix, with its own library')


if __name__ == '__main__':
    main()
