"""The standing fault campaign (``python -m bench faults``): every fault the station must heal from,
injected into a real station running through a pass at virtual speed, with what it cost and whether
STATUS told the truth meanwhile."""
