"""Traceability database: every raw file, condition and derived number, with its provenance.

SQLAlchemy 2 typed ORM, SQLite by default, any SQLAlchemy URL; the schema is
created and upgraded by Alembic migrations (``traceability/migrations``).
"""

from traceability.database import open_database, sqlite_url
from traceability.store import StoreOutcome, store_ingested_run

__all__ = ["open_database", "sqlite_url", "store_ingested_run", "StoreOutcome"]
