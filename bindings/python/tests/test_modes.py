"""Both loading modes: ABI (dlopen, forced with AMSCR_FORCE_ABI=1) and API (compiled extension)
give identical results on the key checks."""
import json
import os
import shutil
import subprocess
import sys

import pytest

import amscr
import keychecks
from conftest import PKG_ROOT

HERE = os.path.dirname(os.path.abspath(__file__))
PKG_PARENT = os.path.dirname(os.path.dirname(os.path.abspath(amscr.__file__)))


def _run(env_extra, pythonpath):
    env = dict(os.environ)
    env.pop('AMSCR_FORCE_ABI', None)
    env.update(env_extra)
    env['PYTHONPATH'] = os.pathsep.join([pythonpath, HERE])
    r = subprocess.run([sys.executable, os.path.join(HERE, 'keychecks.py')], env=env, capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


@pytest.fixture(scope='module')
def here():
    return json.loads(json.dumps(keychecks.run()))


def _same(a, b):
    a, b = dict(a), dict(b)
    a.pop('api_mode'), b.pop('api_mode')
    assert a == b


def test_keychecks_in_process(here):
    assert here['lstsq_ok']
    assert here['error'][0] == 'InvalidArgumentError' and here['error'][1] == 1
    assert here['cancel'] == 'CancelledError'


def test_abi_mode(here):
    got = _run({'AMSCR_FORCE_ABI': '1'}, PKG_PARENT)
    assert got['api_mode'] is False
    _same(got, here)


def test_api_mode(here, tmp_path):
    if amscr.API_MODE:
        got = _run({}, PKG_PARENT)
    else:
        # Not installed with the extension: build it against the in-tree library into a copy.
        try:
            sys.path.insert(0, os.path.join(PKG_ROOT, 'amscr'))
            try:
                import _build
            finally:
                sys.path.pop(0)
            from conftest import BUILD_DIR, REPO_ROOT
            ffibuilder = _build.make_ffibuilder([os.path.join(REPO_ROOT, 'include')], [BUILD_DIR])
        except Exception as e:
            pytest.skip('cannot set up the API-mode build: %s' % e)
        if not (shutil.which('cc') or shutil.which('gcc')):
            pytest.skip('no C compiler for the API-mode build')
        shutil.copytree(os.path.join(PKG_ROOT, 'amscr'), tmp_path / 'amscr',
                        ignore=shutil.ignore_patterns('_amscr*', '__pycache__', '_buildinfo.py'))
        cwd = os.getcwd()
        try:
            ffibuilder.compile(tmpdir=str(tmp_path), verbose=False)
        finally:
            os.chdir(cwd)
        got = _run({}, str(tmp_path))
    assert got['api_mode'] is True
    _same(got, here)
