"""Open a traceability database at any SQLAlchemy URL, upgraded to the newest schema."""

from __future__ import annotations

from pathlib import Path

from alembic import command
from alembic.config import Config
from sqlalchemy import Engine, create_engine, event
from sqlalchemy.orm import Session, sessionmaker

MIGRATIONS = Path(__file__).parent / "migrations"


def sqlite_url(path: str | Path) -> str:
    """The SQLAlchemy URL of a SQLite file (created on first use)."""
    return f"sqlite:///{Path(path).resolve()}"


def _enable_sqlite_foreign_keys(engine: Engine) -> None:
    if engine.dialect.name == "sqlite":
        @event.listens_for(engine, "connect")
        def _fk_on(dbapi_connection, _record):  # noqa: ANN001 - DB-API types
            dbapi_connection.execute("PRAGMA foreign_keys=ON")


def upgrade(engine: Engine) -> None:
    """Run the Alembic migrations up to head on ``engine``."""
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    with engine.begin() as connection:
        config.attributes["connection"] = connection
        command.upgrade(config, "head")


def open_database(url: str) -> sessionmaker[Session]:
    """Create/upgrade the schema at ``url`` and return a session factory bound to it."""
    if url.startswith("sqlite:///"):
        Path(url.removeprefix("sqlite:///")).parent.mkdir(parents=True, exist_ok=True)
    engine = create_engine(url)
    _enable_sqlite_foreign_keys(engine)
    upgrade(engine)
    return sessionmaker(engine, expire_on_commit=False)
