"""Version of the Python package; equal to the C header's AMSCR_VERSION_* (a test checks it)."""
__version__ = "0.22.8"
