"""The scenario file: its dataclasses, reader, key reference and numerics settings."""
