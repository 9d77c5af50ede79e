"""The tutorial of bindings/python/README.md runs: its ```python blocks, in order, as one script,
from a folder where examples/ is the repository's. A block after ``<!-- requires: mod ... -->``
needs those modules and is left out (the test says so) when they are missing.

It runs twice: as is (Pillow reads the images when installed), and with Pillow hidden, where the
tutorial's reader falls back on the ``amscr`` command."""
import builtins
import importlib.util
import os
import re
import shutil

import pytest

from conftest import BUILD_DIR, PKG_ROOT, REPO_ROOT

README = os.path.join(PKG_ROOT, 'README.md')
EXAMPLES = os.path.join(REPO_ROOT, 'examples')
TOOL = os.environ.get('AMSCR_TOOL') or os.path.join(BUILD_DIR, 'tools', 'amscr')
if not os.access(TOOL, os.X_OK):  # the command pip installed, when testing the installed package
    TOOL = shutil.which('amscr') or TOOL
BLOCK = re.compile(r'(?:<!-- requires: ([\w .]+) -->\n)?```python\n(.*?)```', re.S)

pytestmark = pytest.mark.skipif(not (os.path.exists(README) and os.path.isdir(EXAMPLES)),
                                reason='needs the repository: bindings/python/README.md and examples/')


def _blocks():
    """[(required modules, code)] of the README's python blocks."""
    with open(README, encoding='utf-8') as f:
        text = f.read()
    return [((req or '').split(), code) for req, code in BLOCK.findall(text)]


def _available(module):
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):
        return False


def _run_tutorial(tmp_path, monkeypatch, capsys, optional=True):
    """Runs the blocks (those with requirements only when `optional`); returns (namespace,
    [(block, missing modules)] left out, captured output)."""
    (tmp_path / 'examples').symlink_to(EXAMPLES, target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    if os.access(TOOL, os.X_OK):  # the `amscr` command, as pip installs it next to python
        monkeypatch.setenv('PATH', os.path.dirname(os.path.abspath(TOOL)) + os.pathsep + os.environ['PATH'])
    namespace = {'__name__': '__readme__'}
    left_out = []
    for i, (requires, code) in enumerate(_blocks()):
        missing = [m for m in requires if not (optional and _available(m))]
        if missing:
            left_out.append((i, missing))
            continue
        exec(compile(code, '%s (python block %d)' % (README, i + 1), 'exec'), namespace)
    assert sorted(os.listdir(tmp_path)) == ['examples'], 'the tutorial left files behind'
    return namespace, left_out, capsys.readouterr()


def test_readme_has_the_tutorial():
    blocks = _blocks()
    assert len(blocks) >= 4
    code = '\n'.join(c for _, c in blocks)
    for needed in ('amscr.register(', 'Collection(', 'Params.retrieval()', '.query(', 'Index(db)',
                   'retrieval_matrix(progress=True)', "order='rc'", 'cv2.warpAffine', 'AffineTransform(matrix='):
        assert needed in code, needed


def test_tutorial_runs(tmp_path, monkeypatch, capsys):
    ns, left_out, out = _run_tutorial(tmp_path, monkeypatch, capsys)
    assert ns['r'].matrix.shape == (3, 3) and ns['D'].shape == (12, 12)
    assert 'amscr [' in out.err  # the progress bar
    if left_out:
        pytest.skip('ran the tutorial without blocks %s (missing modules)' % left_out)


def test_tutorial_runs_without_pillow(tmp_path, monkeypatch, capsys):
    if not os.access(TOOL, os.X_OK):
        pytest.skip('the amscr command is not built (%s)' % TOOL)
    from amscr._console import tool_path
    if not os.path.isfile(tool_path()):  # the tutorial's `python -m amscr`
        pytest.skip('the package has no bundled amscr command (%s): run from a source tree' % tool_path())
    real_import = builtins.__import__

    def no_pillow(name, *args, **kwargs):
        if name == 'PIL' or name.startswith('PIL.'):
            raise ImportError('Pillow hidden by the test')
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, '__import__', no_pillow)
    ns, _, _ = _run_tutorial(tmp_path, monkeypatch, capsys, optional=False)
    assert ns['r'].distance < 0.01
