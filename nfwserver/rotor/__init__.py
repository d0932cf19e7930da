"""The rotor layer: the Kansas City Tracker driver model, FlipAnts flip planning, backends, autotracking.
"""
