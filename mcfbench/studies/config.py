"""The one error of a bad config value, shared by every study and the Snakemake glue."""


class ConfigError(ValueError):
    """A config value the schema cannot check (a name against a registry, a time
    step, a level); the message names the key."""
