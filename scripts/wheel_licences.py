#!/usr/bin/env python3
"""Puts the licence texts of the libraries a repaired wheel bundles into the wheel.

`auditwheel repair` copies OpenBLAS, LAPACK(E), libpng and the GCC runtime (libgfortran,
libquadmath) into amscr.libs/ and names their Debian packages in the wheel's SBOM
(*.dist-info/sboms/auditwheel.cdx.json). Their licences ask a binary copy to carry their notices,
so each package's /usr/share/doc/PKG/copyright goes into amscr.libs/LICENSES/PKG.copyright, with
the /usr/share/common-licenses texts those files refer to in amscr.libs/LICENSES/common-licenses/,
and amscr.libs/LICENSES/README names which library came from which package. The wheel is
unpacked and packed again (`python -m wheel`: a new RECORD). A package without a copyright file
is an error: a wheel never ships without the notices.

    scripts/wheel_licences.py WHEEL
"""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import urllib.parse

DOC = '/usr/share/doc'
COMMON = '/usr/share/common-licenses'


def sbom_packages(root):
    """{Debian package: version} of the SBOM's deb components (or asked of dpkg where the wheel has
    no SBOM), and the bundled libraries."""
    info = next(d for d in os.listdir(root) if d.endswith('.dist-info'))
    libs = sorted(n for n in os.listdir(os.path.join(root, 'amscr.libs')) if '.so' in n)
    path = os.path.join(root, info, 'sboms', 'auditwheel.cdx.json')
    if not os.path.isfile(path):
        return dpkg_packages(libs), libs
    with open(path, encoding='utf-8') as f:
        sbom = json.load(f)
    pkgs = {}
    for c in sbom.get('components', []):
        purl = c.get('purl', '')
        if purl.startswith('pkg:deb/'):
            pkgs[c['name']] = urllib.parse.unquote(c.get('version', ''))
    return pkgs, libs


def dpkg_packages(libs):
    """{Debian package: version} of the bundled libraries, asked of dpkg. auditwheel writes no SBOM
    where a package is installed for two architectures (its `dpkg -s NAME` is then ambiguous): the
    library's file is looked up under this machine's multiarch folder, its package named with its
    architecture."""
    arch = subprocess.run(['gcc', '-print-multiarch'], capture_output=True, text=True).stdout.strip()
    pkgs = {}
    for lib in libs:
        m = re.match(r'^(.*)-[0-9a-f]{8}(\..*)$', lib)  # auditwheel's name: the original's, a hash inserted
        found = subprocess.run(['dpkg', '-S', '*/' + (m.group(1) + m.group(2) if m else lib)],
                               capture_output=True, text=True).stdout.splitlines()
        hits = [line.split(': ', 1)[0].split(', ')[0] for line in found if '/%s/' % arch in line or not arch]
        if not hits:
            sys.exit('wheel_licences: no Debian package holds %s (the SBOM is missing)' % lib)
        version = subprocess.run(['dpkg-query', '-W', '-f=${Version}', hits[0]], capture_output=True,
                                 text=True, check=True).stdout
        pkgs[hits[0].split(':')[0]] = version
    return pkgs


def copy_notices(pkgs, libs, out):
    """The copyright file of every package, the common licences they cite, and a README."""
    os.makedirs(os.path.join(out, 'common-licenses'))
    cited = set()
    for pkg in sorted(pkgs):
        src = os.path.join(DOC, pkg, 'copyright')
        if not os.path.isfile(src):
            sys.exit('wheel_licences: %s has no %s: cannot ship its library without its notice' % (pkg, src))
        shutil.copyfile(src, os.path.join(out, pkg + '.copyright'))
        with open(src, encoding='utf-8', errors='replace') as f:
            cited.update(re.findall(re.escape(COMMON) + r'/([A-Za-z0-9+-]+(?:\.[0-9]+)*)', f.read()))
    for name in sorted(cited):
        if os.path.isfile(os.path.join(COMMON, name)):
            shutil.copyfile(os.path.join(COMMON, name), os.path.join(out, 'common-licenses', name))
    lines = ['Libraries bundled in amscr.libs/ and the Debian packages they were copied from',
             '(each package\'s licence and copyright notice: PACKAGE.copyright; the licence texts',
             'they cite: common-licenses/).', '', 'libraries: ' + ' '.join(libs), '']
    lines += ['%s %s' % (p, v) for p, v in sorted(pkgs.items())]
    with open(os.path.join(out, 'README'), 'w', encoding='utf-8') as f:
        f.write('\n'.join(lines) + '\n')
    return sorted(pkgs), sorted(cited)


def main(argv):
    if len(argv) != 2:
        sys.exit(__doc__.strip().splitlines()[-1].strip())
    wheel = os.path.abspath(argv[1])
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([sys.executable, '-m', 'wheel', 'unpack', '-d', tmp, wheel], check=True,
                       stdout=subprocess.DEVNULL)
        root = os.path.join(tmp, os.listdir(tmp)[0])
        pkgs, libs = sbom_packages(root)
        if not pkgs:
            sys.exit('wheel_licences: the SBOM of %s names no Debian package' % wheel)
        names, cited = copy_notices(pkgs, libs, os.path.join(root, 'amscr.libs', 'LICENSES'))
        packed = os.path.join(tmp, 'packed')
        os.mkdir(packed)
        subprocess.run([sys.executable, '-m', 'wheel', 'pack', '-d', packed, root], check=True,
                       stdout=subprocess.DEVNULL)
        (new,) = os.listdir(packed)
        if new != os.path.basename(wheel):
            sys.exit('wheel_licences: packed %s, expected %s' % (new, os.path.basename(wheel)))
        shutil.move(os.path.join(packed, new), wheel)
    print('wheel_licences: %s: the notices of %s (common licences: %s)' %
          (os.path.basename(wheel), ', '.join(names), ', '.join(cited) or 'none'))


if __name__ == '__main__':
    main(sys.argv)
