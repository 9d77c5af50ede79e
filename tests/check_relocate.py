#!/usr/bin/env python3
"""The installed `amscr` tool runs from a prefix moved after the install (here: staged with DESTDIR,
the prefix itself never created) and loads the library installed beside it, not another one.

    check_relocate.py MESON SOURCE_ROOT

Configures the project in a temporary folder (no tests, no benchmarks), builds the library and the
tool, installs them with DESTDIR and runs the staged tool with no LD_LIBRARY_PATH.
"""
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
    meson, source_root = sys.argv[1], os.path.realpath(sys.argv[2])
    with tempfile.TemporaryDirectory(prefix='amscr-relocate-') as tmp:
        build, prefix, stage = (os.path.join(tmp, d) for d in ('b', 'prefix', 'stage'))
        run([meson, 'setup', build, source_root, '--prefix', prefix, '-Dtests=disabled', '-Dbench=false',
             '-Dpng=disabled', '-Dtest_python=' + sys.executable])
        run([meson, 'compile', '-C', build, 'amscr:shared_library', 'tools/amscr'])
        run([meson, 'install', '-C', build, '--no-rebuild', '--destdir', stage])
        staged = stage + prefix
        tool = os.path.join(staged, 'bin', 'amscr')
        assert not os.path.exists(prefix)
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
