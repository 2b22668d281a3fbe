"""A researcher's own scheme, outside the suite: joins it by an entry point."""
