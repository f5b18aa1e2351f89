"""Channel maps shipped with ingest (TOML package data; see docs/channel-map.md)."""
