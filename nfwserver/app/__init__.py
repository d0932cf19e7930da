"""Assembly of the running product from a validated configuration."""
