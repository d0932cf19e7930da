"""Configuration: one table of sections and keys, from which validation, ``config show`` and the
``config init`` template are generated; the TOML file's location; reading user files safely.

The names below are imported on first use (:mod:`nfwserver.lazy_exports`): reading a file through
:mod:`nfwserver.config.files`, or a default from :mod:`nfwserver.config.table`, does not build the
configuration's record types (:mod:`nfwserver.config.schema`), which cost a command as much at start as a
day of one satellite's passes.
"""

from typing import TYPE_CHECKING

from nfwserver.lazy_exports import lazy_exports

_EXPORTS = {"MAX_FILE_BYTES": "files", "FileRefused": "files", "read_regular_file": "files",
            "default_config_path": "files", "ConfigError": "loader", "load_config": "loader",
            "observer_hint": "loader", "parse_config": "loader", "Config": "schema", "EasyCommConfig": "schema",
            "TcpConfig": "schema"}
__all__ = sorted(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)

if TYPE_CHECKING:  # the names as type checkers see them; at run time each module loads on first use
    from nfwserver.config.files import MAX_FILE_BYTES as MAX_FILE_BYTES
    from nfwserver.config.files import FileRefused as FileRefused
    from nfwserver.config.files import default_config_path as default_config_path
    from nfwserver.config.files import read_regular_file as read_regular_file
    from nfwserver.config.loader import ConfigError as ConfigError
    from nfwserver.config.loader import load_config as load_config
    from nfwserver.config.loader import observer_hint as observer_hint
    from nfwserver.config.loader import parse_config as parse_config
    from nfwserver.config.schema import Config as Config
    from nfwserver.config.schema import EasyCommConfig as EasyCommConfig
    from nfwserver.config.schema import TcpConfig as TcpConfig
