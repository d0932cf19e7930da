"""The web dashboard: the live station in a browser, served by the station itself (issue 26).

One more adapter beside Nova's TCP server (docs/WEB.md): it reads the one live station state and the
tick stream, sends commands through the station core's command entry, and adds to the publish loop
only the hand-over of the newest sample.

- :mod:`~nfwserver.web.server`: :class:`WebServer`, the listener and its life cycle, the frame thread.
- :mod:`~nfwserver.web.hub`: the newest frame, handed to every browser (newest wins, nothing queued).
- :mod:`~nfwserver.web.handler`: HTTP routes (page, assets, ``/api/state``, ``/api/passes``, the event
  stream, ``/api/command``).
- :mod:`~nfwserver.web.state_view` and :mod:`~nfwserver.web.station_parts`: the JSON the page shows.
- :mod:`~nfwserver.web.pass_board`: passes, the pass track and the ground track, computed off the loop.
- :mod:`~nfwserver.web.control`: who may send a command, and sending it.
"""

from nfwserver.web.server import WebServer
from nfwserver.web.station_parts import StationParts

__all__ = ["StationParts", "WebServer"]
