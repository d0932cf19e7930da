"""Hamlib's network daemons (rigctld, rotctld): the line protocol client shared by radio and rotor."""
