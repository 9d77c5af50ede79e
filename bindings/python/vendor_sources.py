"""meson dist script: puts a real copy of the C sources into the sdist.

In a checkout, subprojects/amscr is a link to the repository root; `meson dist` archives the link
itself, which would dangle in the sdist. This replaces it with the files the library and the tool
are built from (the ones git tracks), so `pip install amscr-X.tar.gz` builds on its own.
"""
import os
import shutil
import subprocess
import sys

# What the root meson.build reads when it is the package's subproject (tests and benchmarks are
# skipped there).
PATHS = ['meson.build', 'meson_options.txt', 'include', 'src', 'tools', 'scripts']


def main():
    dist_root = os.environ['MESON_DIST_ROOT']
    repo = os.path.realpath(os.path.join(os.environ['MESON_SOURCE_ROOT'], 'subprojects', 'amscr'))
    target = os.path.join(dist_root, 'subprojects', 'amscr')
    if os.path.islink(target) or os.path.isfile(target):
        os.remove(target)
    elif os.path.isdir(target):
        shutil.rmtree(target)
    files = subprocess.run(['git', 'ls-files', '-z', '--', *PATHS], cwd=repo, check=True,
                           capture_output=True).stdout.decode().split('\0')
    files = [f for f in files if f and os.path.isfile(os.path.join(repo, f))]
    missing = [p for p in PATHS if not any(f == p or f.startswith(p + '/') for f in files)]
    if missing:
        sys.exit('vendor_sources.py: not tracked by git in %s: %s' % (repo, ', '.join(missing)))
    for f in files:
        dst = os.path.join(target, f)
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        shutil.copy2(os.path.join(repo, f), dst)
    print('vendor_sources.py: %d files of %s copied into the sdist' % (len(files), repo))


if __name__ == '__main__':
    main()
