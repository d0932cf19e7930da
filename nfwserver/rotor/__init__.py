"""Rotor layer: the Kansas City Tracker driver model, rotor geometry and flip tracking, backends."""
