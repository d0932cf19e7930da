"""Autotrack: an unattended station that works the passes of its list by priority, by itself (issue 43).

- :mod:`~nfwserver.autotrack.rule`: which passes are scheduled and which are left out (the rule);
- :mod:`~nfwserver.autotrack.schedule`: a schedule's records (:class:`PlannedPass`, :class:`Schedule`);
- :mod:`~nfwserver.autotrack.planner`: the candidate passes from the pass search, and the station's planner;
- :mod:`~nfwserver.autotrack.runtime`: following ticks, re-planning, selecting (:class:`AutotrackRuntime`);
- :mod:`~nfwserver.autotrack.worker`: the runtime on the station's ticks, on its own thread.

docs/AUTOTRACK.md gives the rule with a worked example.
"""

from nfwserver.autotrack.planner import AutotrackSettings, StationPlanner, plan_schedule, resolve_satellites
from nfwserver.autotrack.runtime import AutotrackRuntime, AutotrackStatus
from nfwserver.autotrack.schedule import PlannedPass, Schedule

__all__ = ["AutotrackRuntime", "AutotrackSettings", "AutotrackStatus", "PlannedPass", "Schedule", "StationPlanner",
           "plan_schedule", "resolve_satellites"]
