"""The hostile-input and fault campaign behind ``python -m bench reliability`` (issue 18, "The standing campaign").

One module per concern: :mod:`tally` counts inputs, crashes, tracebacks and lost data; :mod:`fuzz_elements`,
:mod:`fuzz_lines` generate seeded hostile inputs; :mod:`station_rig` runs a real Station with its listeners
and watching clients; :mod:`input_families`, :mod:`fault_families` and :mod:`realtime` run the families.
Every loop is bounded by a count or a duration given by the caller (:class:`Budget`).
"""
