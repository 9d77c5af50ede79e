"""meson dist script: puts a real copy of the C sources into the sdist.

In a checkout, subprojects/amscr is a link to the repository root; `meson dist` archives the link
itself, which would dangle in the sdist. This replaces it with the files the library and the tool
are built from, as committed (git's HEAD, as `meson dist` takes the package's own files: an
uncommitted change is in neither), so `pip install amscr-X.tar.gz` builds on its own.
"""
import io
import os
import shutil
import subprocess
import sys
import tarfile

# What the root meson.build reads when it is the package's subproject (tests and benchmarks are
# skipped there), and the licence the package installs.
PATHS = ['meson.build', 'meson_options.txt', 'include', 'src', 'tools', 'scripts', 'LICENSE']


def main():
    dist_root = os.environ['MESON_DIST_ROOT']
    repo = os.path.realpath(os.path.join(os.environ['MESON_SOURCE_ROOT'], 'subprojects', 'amscr'))
    target = os.path.join(dist_root, 'subprojects', 'amscr')
    if os.path.islink(target) or os.path.isfile(target):
        os.remove(target)
    elif os.path.isdir(target):
        shutil.rmtree(target)
    tar_bytes = subprocess.run(['git', 'archive', '--format=tar', 'HEAD', '--', *PATHS], cwd=repo, check=True,
                               capture_output=True).stdout
    with tarfile.open(fileobj=io.BytesIO(tar_bytes)) as tar:
        files = [m.name for m in tar.getmembers() if m.isfile()]
        missing = [p for p in PATHS if not any(f == p or f.startswith(p + '/') for f in files)]
        if missing:
            sys.exit('vendor_sources.py: not committed in %s: %s' % (repo, ', '.join(missing)))
        if hasattr(tarfile, 'data_filter'):
            tar.extractall(target, filter='data')
        else:
            tar.extractall(target)
    print('vendor_sources.py: %d files of %s copied into the sdist' % (len(files), repo))


if __name__ == '__main__':
    main()
