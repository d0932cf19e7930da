"""Configuration: the TOML file's schema, validation, location and starting template."""

from nfwserver.config.loader import ConfigError, default_config_path, load_config, parse_config
from nfwserver.config.schema import Config

__all__ = ["Config", "ConfigError", "default_config_path", "load_config", "parse_config"]
