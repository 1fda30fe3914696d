"""Type stubs of the native module `hil._hil`."""

__version__: str
