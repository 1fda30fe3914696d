"""hil: human-in-the-loop contextual bandits for assistive robotics.

Python bindings of the hil Rust toolkit. The bundled data is synthetic,
calibrated to published figures; results computed from it are not the
paper's results.
"""

from ._hil import __version__

__all__ = ["__version__"]
