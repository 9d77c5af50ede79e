"""The ``amscr`` command of an installed package: runs the command-line tool bundled beside this file.

pip writes a launcher for it into the environment's ``bin/`` (``[project.scripts]`` in
pyproject.toml). On POSIX the tool replaces this process (``execv``), so its exit status, its
output and signals are exactly the tool's own.
"""
import os
import subprocess
import sys

_HERE = os.path.dirname(os.path.abspath(__file__))


def tool_path():
    """Path of the bundled ``amscr`` executable (``amscr.exe`` on Windows)."""
    return os.path.join(_HERE, 'amscr.exe' if os.name == 'nt' else 'amscr')


def main(argv=None):
    """Runs the bundled tool with ``argv`` (default: this process's arguments); does not return on POSIX."""
    args = sys.argv[1:] if argv is None else list(argv)
    exe = tool_path()
    if not os.path.isfile(exe):
        sys.stderr.write('amscr: the command-line tool is not in the package (%s); reinstall amscr with pip\n' % exe)
        return 127
    if os.name == 'posix':
        sys.stdout.flush()
        sys.stderr.flush()
        os.execv(exe, ['amscr'] + args)
    return subprocess.call([exe] + args)


if __name__ == '__main__':
    sys.exit(main())
