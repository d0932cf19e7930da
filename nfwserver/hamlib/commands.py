"""The Hamlib daemon commands nfwserver uses, as a table: name, command letter, arguments, reply lines.

rotctld and rigctld answer a *set* command with one ``RPRT n`` line and a *get* command with its
values (one per line), ``RPRT n`` only on failure; an unknown command gets no reply and a missing
argument makes the daemon wait for more input (Hamlib 4.5.4).  So every command goes through
:meth:`HamlibCommand.line`, which refuses a wrong number of arguments before anything is sent, and
:meth:`nfwserver.hamlib.connection.HamlibConnection.call` reads exactly :attr:`reply_lines` values.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class HamlibCommand:
    name: str  #: Hamlib's long name (for messages)
    letter: str  #: the short command sent on the wire
    arguments: int  #: number of arguments the daemon expects
    reply_lines: int  #: value lines answered on success; 0: a set command, answered by ``RPRT``

    def line(self, *args: object) -> str:
        """The command line to send; :class:`ValueError` for a wrong argument count or a line break."""
        if len(args) != self.arguments:
            raise ValueError(f"{self.name} takes {self.arguments} argument(s), got {len(args)}")
        text = " ".join([self.letter, *(str(a) for a in args)])
        if "\n" in text or "\r" in text:
            raise ValueError("a Hamlib command is one line")
        return text


# rotctld (rotator daemon): positions in degrees, in the rotor's own frame.
SET_POSITION = HamlibCommand("set_pos", "P", 2, 0)
GET_POSITION = HamlibCommand("get_pos", "p", 0, 2)
STOP_ROTOR = HamlibCommand("stop", "S", 0, 0)

# rigctld (rig daemon): frequencies in Hz; VFO A receives, the split VFO transmits.
SET_FREQUENCY = HamlibCommand("set_freq", "F", 1, 0)
GET_FREQUENCY = HamlibCommand("get_freq", "f", 0, 1)
SET_SPLIT_FREQUENCY = HamlibCommand("set_split_freq", "I", 1, 0)
GET_SPLIT_FREQUENCY = HamlibCommand("get_split_freq", "i", 0, 1)
SET_SPLIT_VFO = HamlibCommand("set_split_vfo", "S", 2, 0)
SET_MODE = HamlibCommand("set_mode", "M", 2, 0)
SET_SPLIT_MODE = HamlibCommand("set_split_mode", "X", 2, 0)
