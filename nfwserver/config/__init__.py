"""Configuration: one table of sections and keys, from which validation, ``config show`` and the
``config init`` template are generated; the TOML file's location; reading user files safely."""

from nfwserver.config.files import MAX_FILE_BYTES, FileRefused, read_regular_file
from nfwserver.config.loader import ConfigError, default_config_path, load_config, observer_hint, parse_config
from nfwserver.config.schema import Config, EasyCommConfig, TcpConfig

__all__ = ["MAX_FILE_BYTES", "Config", "ConfigError", "EasyCommConfig", "FileRefused", "TcpConfig",
           "default_config_path", "load_config", "observer_hint", "parse_config", "read_regular_file"]
