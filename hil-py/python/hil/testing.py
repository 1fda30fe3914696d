"""hil's conformance suites, run on Python components.

The same checks every Rust and plugin implementation passes
(``hil_conformance``). Each returns a report dict (``subject``,
``passed``, ``skipped``) or raises :class:`hil.ConformanceError` whose
``check`` names the failed check and ``hint`` says the likely cause and fix.
"""

from ._hil import testing as _native

check_policy = _native.check_policy
check_environment = _native.check_environment
check_workload_model = _native.check_workload_model
check_query_channel = _native.check_query_channel

__all__ = ["check_environment", "check_policy", "check_query_channel", "check_workload_model"]
