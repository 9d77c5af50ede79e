"""The files of a saved shard set (``amscr.distributed``; :mod:`amscr._shards` holds the set in
memory): a directory with ``manifest.json`` (written last, by an atomic rename: the commit point),
one ``shard-SSS-CHECKSUM.amscr-index`` per shard (an ordinary index file) and
``graph-CHECKSUM.npz`` (the global lists), each named by its SHA-256. Written through temporary
files renamed into place (mode 0666 less the umask); read with every file checked against the
manifest.
"""
from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import os
import re
import tempfile
from typing import Any, Dict, List, Tuple

from ._lib import lib
from .errors import AmscrError, FileError, FormatError
from .index import Index
from .params import Params, _params_from_dict

FORMAT = 'amscr-sharded-index'
VERSION = 1
MANIFEST = 'manifest.json'
#: The folder's lock: a save holds it alone, loads share it (flock), so saves into one folder at once
#: follow each other and a load never reads a set half replaced.
LOCK = '.amscr-lock'


class ShardSetError(AmscrError, ValueError):
    """A saved shard set that cannot be used: a shard file missing, foreign (another set's, or
    altered) or built with other options than the manifest's. The message names the file."""


@contextlib.contextmanager
def _locked(d: str, exclusive: bool) -> Any:
    """Directory d's lock (LOCK) held for the block: alone for a save, shared for a load (each waits
    for the other). A folder where the lock cannot be made (read-only) is read without it."""
    try:
        fd = os.open(os.path.join(d, LOCK), os.O_RDWR | os.O_CREAT | getattr(os, 'O_CLOEXEC', 0), 0o666)
    except OSError as e:
        if exclusive:
            raise FileError('%s: cannot lock the set\'s folder: %s' % (d, e.strerror), lib.AMSCR_E_IO) from None
        yield
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH)
        yield
    finally:
        os.close(fd)


def prepare_dir(path: Any) -> str:
    """The set's directory `path` made if needed and checked writable (before any work: a build
    does not fail after its work for a folder it cannot write)."""
    d = os.fspath(path)
    try:
        os.makedirs(d, exist_ok=True)
    except OSError as e:
        raise FileError('%s: cannot make the set\'s folder: %s' % (d or "''", e.strerror or e), lib.AMSCR_E_IO) from None
    if not os.access(d, os.W_OK | os.X_OK):
        raise FileError('%s: the set\'s folder is not writable' % d, lib.AMSCR_E_IO)
    return d


def write_set(d: str, datas: List[bytes], bounds: List[Tuple[int, int]], gdata: bytes, n: int, params: Params,
              candidates: int) -> None:
    """The shard files and the graph into directory d, then the manifest, then the files of the set
    it replaces (and leftovers of cut-off writes) removed; under the folder's lock."""
    with _locked(d, True):
        _write_set(d, datas, bounds, gdata, n, params, candidates)


def _write_set(d: str, datas: List[bytes], bounds: List[Tuple[int, int]], gdata: bytes, n: int, params: Params,
               candidates: int) -> None:
    entries = []
    keep = {MANIFEST}
    for s, data in enumerate(datas):
        sha = hashlib.sha256(data).hexdigest()
        name = 'shard-%03d-%s.amscr-index' % (s, sha[:16])
        _write_atomic(d, name, data)
        keep.add(name)
        entries.append({'file': name, 'sha256': sha, 'first': bounds[s][0], 'count':
                        bounds[s][1] - bounds[s][0]})
    gsha = hashlib.sha256(gdata).hexdigest()
    gname = 'graph-%s.npz' % gsha[:16]
    _write_atomic(d, gname, gdata)
    keep.add(gname)
    manifest = {'format': FORMAT, 'version': VERSION, 'shapes': n, 'params': params._plain_dict(),
                'shards': entries, 'graph': {'file': gname, 'sha256': gsha}, 'candidates': candidates}
    _write_atomic(d, MANIFEST, (json.dumps(manifest, indent=1, sort_keys=True) + '\n').encode())
    for f in os.listdir(d):  # the replaced set's files and leftovers of cut-off writes
        if f not in keep and (_ours(f)):
            try:
                os.unlink(os.path.join(d, f))
            except OSError:
                pass


#: The names a save writes (write_set): shard-SSS-HEX16.amscr-index, graph-HEX16.npz, and its temporaries.
_OURS = re.compile(r'(shard-[0-9]{3,}-[0-9a-f]{16}\.amscr-index|graph-[0-9a-f]{16}\.npz|\.amscr-tmp-.*)')


def _ours(f: str) -> bool:
    return _OURS.fullmatch(f) is not None


def _umask() -> int:
    """The process's umask, read without changing it where Linux tells it (os.umask changes it
    for every thread while it is read)."""
    try:
        with open('/proc/self/status') as f:
            for line in f:
                if line.startswith('Umask:'):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _write_atomic(d: str, name: str, data: bytes) -> None:
    """Writes d/name by a temporary file in d, fsync and rename; mode 0666 less the umask."""
    fd, tmp = tempfile.mkstemp(prefix='.amscr-tmp-', dir=d)
    try:
        try:
            with os.fdopen(fd, 'wb') as f:
                f.write(data)
                f.flush()
                os.fsync(f.fileno())
            os.chmod(tmp, 0o666 & ~_umask())
            os.replace(tmp, os.path.join(d, name))
        except BaseException:
            os.unlink(tmp)
            raise
    except OSError as e:
        raise FileError('amscr.distributed: cannot write %s: %s' % (os.path.join(d, name), e.strerror or e),
                        lib.AMSCR_E_IO) from e
    try:
        dfd = os.open(d, os.O_RDONLY)
        try:
            os.fsync(dfd)
        finally:
            os.close(dfd)
    except OSError:  # pragma: no cover - a file system without directory fsync
        pass


def _read_manifest(d: str) -> Dict[str, Any]:
    p = os.path.join(d, MANIFEST)
    try:
        with open(p, 'rb') as f:
            m = json.loads(f.read().decode('utf-8'))
    except FileNotFoundError:
        raise FileError('amscr.distributed.load_index: no shard set in %s (%s is missing)' % (d, MANIFEST),
                        lib.AMSCR_E_IO) from None
    except (ValueError, UnicodeDecodeError) as e:
        raise FormatError('amscr.distributed.load_index: %s is not a shard set manifest: %s' % (p, e),
                          lib.AMSCR_E_FORMAT) from None
    if not isinstance(m, dict) or m.get('format') != FORMAT:
        raise FormatError('amscr.distributed.load_index: %s is not a shard set manifest' % p, lib.AMSCR_E_FORMAT)
    if m.get('version') != VERSION:
        raise FormatError('amscr.distributed.load_index: %s is of version %r; this amscr reads version %d'
                          % (p, m.get('version'), VERSION), lib.AMSCR_E_FORMAT)
    return m


def check_shard(d: str, s: int, name: str, count: int, params: Params, got: Tuple[int, Dict[str, Any]]) -> None:
    """Shard s (file `name` of directory d), loaded, holds `count` shapes built with `params`, as the
    manifest says (its checksum vouches for its bytes, not for the manifest's other entries)."""
    p = os.path.join(d, name)
    if got[0] != count:
        raise ShardSetError('amscr.distributed.load_index: shard %d, %s, holds %d shapes; the manifest says %d'
                            % (s, p, got[0], count), lib.AMSCR_E_FORMAT)
    diff = _differing(params._plain_dict(), got[1])
    if diff:
        raise ShardSetError('amscr.distributed.load_index: shard %d, %s, was built with other options than the '
                            'manifest says: %s' % (s, p, '; '.join(diff)), lib.AMSCR_E_FORMAT)


def _differing(a: Dict[str, Any], b: Dict[str, Any]) -> List[str]:
    skip = {'threads'}
    return ['%s %r (the manifest: %r)' % (key, b.get(key), a.get(key)) for key in sorted(set(a) | set(b))
            if key not in skip and a.get(key) != b.get(key)]


def _read_shard(d: str, s: int, entry: Dict[str, Any], params: Params) -> bytes:
    """Shard s's bytes, checked against the manifest (ShardSetError naming the file otherwise)."""
    name = str(entry.get('file'))
    p = os.path.join(d, name)
    try:
        with open(p, 'rb') as f:
            data = f.read()
    except FileNotFoundError:
        raise ShardSetError('amscr.distributed.load_index: shard %d of %s, %s, is missing' % (s, d, name),
                            lib.AMSCR_E_IO) from None
    except OSError as e:
        raise FileError('amscr.distributed.load_index: cannot read shard %d, %s: %s' % (s, p, e.strerror),
                        lib.AMSCR_E_IO) from None
    if hashlib.sha256(data).hexdigest() == entry.get('sha256'):
        return data
    try:  # tell what differs
        x = Index.from_bytes(data)
    except AmscrError:
        raise ShardSetError('amscr.distributed.load_index: shard %d, %s, is not an index file (its checksum '
                            'differs from the manifest\'s)' % (s, p), lib.AMSCR_E_FORMAT) from None
    diff = _differing(params._plain_dict(), x.collection_params()._plain_dict())
    if diff:
        raise ShardSetError('amscr.distributed.load_index: shard %d, %s, was built with other options than the '
                            'set: %s' % (s, p, '; '.join(diff)), lib.AMSCR_E_FORMAT)
    raise ShardSetError('amscr.distributed.load_index: shard %d, %s, is foreign to this set (%d shapes, the '
                        'manifest %s; its checksum differs from the manifest\'s: another set\'s shard, or '
                        'altered)' % (s, p, len(x), entry.get('count')), lib.AMSCR_E_FORMAT)


def read_set(d: str) -> Tuple[Params, int, List[Tuple[int, int]], int, str, bytes, List[bytes], List[str]]:
    """The set in directory d: its params, shape count, shard bounds, candidates, the graph's path
    and bytes, every shard's bytes, each checked against the manifest, and the shards' file names;
    under the folder's lock, shared (a save under way is waited for)."""
    if not os.path.isdir(d):
        return _read_set(d)  # _read_manifest's error
    with _locked(d, False):
        return _read_set(d)


def _read_set(d: str) -> Tuple[Params, int, List[Tuple[int, int]], int, str, bytes, List[bytes], List[str]]:
    m = _read_manifest(d)
    try:
        params = _params_from_dict(m['params'])
        n = int(m['shapes'])
        entries = list(m['shards'])
        bounds = [(int(e['first']), int(e['first']) + int(e['count'])) for e in entries]
        gentry = m['graph']
        candidates = int(m.get('candidates', 0))
        if candidates < 0:
            raise ValueError('candidates %d' % candidates)
        for f in [e['file'] for e in entries] + [gentry['file']]:  # the set's own names, in its folder
            if not isinstance(f, str) or not _ours(f) or f.startswith('.'):
                raise ValueError('file %r is not a name a save writes' % (f,))
    except (KeyError, TypeError, ValueError) as e:
        raise FormatError('amscr.distributed.load_index: %s: a malformed manifest (%s)' % (os.path.join(d, MANIFEST), e),
                          lib.AMSCR_E_FORMAT) from None
    if [b[0] for b in bounds] != [0] + [b[1] for b in bounds[:-1]] or (bounds and bounds[-1][1] != n):
        raise FormatError('amscr.distributed.load_index: %s: shards do not cover the %d shapes in order'
                          % (os.path.join(d, MANIFEST), n), lib.AMSCR_E_FORMAT)
    gp = os.path.join(d, str(gentry.get('file')))
    try:
        with open(gp, 'rb') as f:
            gdata = f.read()
    except FileNotFoundError:
        raise ShardSetError('amscr.distributed.load_index: the graph of %s, %s, is missing' % (d, gentry.get('file')),
                            lib.AMSCR_E_IO) from None
    if hashlib.sha256(gdata).hexdigest() != gentry.get('sha256'):
        raise ShardSetError('amscr.distributed.load_index: the graph %s is foreign to this set (its checksum '
                            'differs from the manifest\'s)' % gp, lib.AMSCR_E_FORMAT)
    datas = [_read_shard(d, s, e, params) for s, e in enumerate(entries)]
    return params, n, bounds, candidates, gp, gdata, datas, [str(e['file']) for e in entries]
