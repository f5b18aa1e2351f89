"""Open a traceability database at any SQLAlchemy URL (docs/results.md, "The database").

Three ways to open one: to create or upgrade it (``swtlab process``, ``swtlab migrate``), to
write into an existing one at this swtlab's schema (``export``, ``gap``), or to read one
(``results``, ``report``). Only the first creates a file or runs a migration; the others
raise :class:`UnusableDatabase` (one line, naming the host, never the password) when the
database is missing, unreachable, not swtlab's, or at an older schema.

Writers never race: every writing transaction holds the database's one write lock
(``BEGIN IMMEDIATE`` on SQLite, a transaction-level advisory lock on PostgreSQL), migrations
included, and :func:`in_transaction` retries a transaction that met a lock, with backoff.
"""

from __future__ import annotations

import random
import time
from pathlib import Path
from typing import Callable, TypeVar

from alembic import command
from alembic.config import Config
from alembic.migration import MigrationContext
from alembic.script import ScriptDirectory
from sqlalchemy import Engine, create_engine, event
from sqlalchemy.engine import URL, make_url
from sqlalchemy.exc import ArgumentError, DBAPIError, IntegrityError, OperationalError
from sqlalchemy.orm import Session, sessionmaker

from swtlab_base.errors import InputError

MIGRATIONS = Path(__file__).parent / "migrations"
#: the PostgreSQL advisory-lock key every swtlab writer takes (``pg_advisory_xact_lock``)
WRITE_LOCK_KEY = 0x5717AB
#: seconds a SQLite connection waits for the write lock before the retry loop takes over
SQLITE_BUSY_TIMEOUT_S = 30.0
#: seconds to reach a PostgreSQL server before giving up
CONNECT_TIMEOUT_S = 10
UPGRADE_COMMAND = "swtlab migrate --db URL"

T = TypeVar("T")


class UnusableDatabase(InputError):
    """A database that cannot be used as asked: missing, unreachable, refused, wrong schema."""


def sqlite_url(path: str | Path) -> str:
    """The SQLAlchemy URL of a SQLite file."""
    return f"sqlite:///{Path(path).resolve()}"


def database_url(text: str) -> str:
    """The SQLAlchemy URL of what a user typed: a plain path is a SQLite file, ``postgres://``
    and ``postgresql://`` use psycopg (the driver swtlab installs)."""
    text = str(text)
    if "://" not in text:
        return sqlite_url(text)
    scheme, rest = text.split("://", 1)
    if scheme in ("postgres", "postgresql"):
        return f"postgresql+psycopg://{rest}"
    return text


def _sqlite_file(url: URL) -> Path | None:
    """The file of a SQLite URL, None for an in-memory database."""
    if url.get_backend_name() != "sqlite" or url.database in (None, "", ":memory:"):
        return None
    return Path(url.database)


def database_file(text: str) -> tuple[Path, bool] | None:
    """The SQLite file a ``--db`` value names, resolved, and whether the URL gave it relative
    to the working directory (``sqlite:///out/x.sqlite``: three slashes, then a relative
    path; ``sqlite:////tmp/x.sqlite`` is absolute); None for other databases."""
    try:
        path = _sqlite_file(make_url(database_url(text)))
    except ArgumentError:
        return None
    return None if path is None else (path.resolve(), not path.is_absolute())


def _shown(url: URL) -> str:
    """The URL to name in a message: without its password."""
    return url.render_as_string(hide_password=True)


def _engine(url: URL, writer: bool) -> Engine:
    backend = url.get_backend_name()
    connect_args = ({"timeout": SQLITE_BUSY_TIMEOUT_S} if backend == "sqlite" else
                    {"connect_timeout": CONNECT_TIMEOUT_S} if backend == "postgresql" else {})
    engine = create_engine(url, connect_args=connect_args)
    if backend == "sqlite":
        @event.listens_for(engine, "connect")
        def _sqlite_connect(dbapi_connection, _record):
            dbapi_connection.isolation_level = None  # transactions begin below, not in pysqlite
            dbapi_connection.execute("PRAGMA foreign_keys=ON")

        @event.listens_for(engine, "begin")
        def _sqlite_begin(connection):
            connection.exec_driver_sql("BEGIN IMMEDIATE" if writer else "BEGIN")
    elif backend == "postgresql" and writer:
        @event.listens_for(engine, "begin")
        def _pg_begin(connection):
            connection.exec_driver_sql(f"SELECT pg_advisory_xact_lock({WRITE_LOCK_KEY})")
    return engine


def _config() -> Config:
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    return config


def head_revision() -> str:
    """The schema revision this swtlab writes."""
    return ScriptDirectory.from_config(_config()).get_current_head()


def upgrade(engine: Engine) -> None:
    """Run the Alembic migrations up to head on ``engine`` (under the write lock of an engine
    opened by :func:`open_database`). On SQLite the foreign keys are off while they run: a
    batch migration rebuilds a table (copy, drop, rename), which a referenced table with
    rows fails under ``PRAGMA foreign_keys=ON`` (SQLite, "ALTER TABLE": the twelve steps);
    the keys are checked once the migrations are done."""
    config = _config()
    sqlite = engine.dialect.name == "sqlite"
    with engine.connect() as connection:
        raw = connection.connection.driver_connection
        if sqlite:  # outside any transaction: the pragma is a no-op inside one
            raw.execute("PRAGMA foreign_keys=OFF")
        try:
            with connection.begin():
                config.attributes["connection"] = connection
                command.upgrade(config, "head")
                broken = (connection.exec_driver_sql("PRAGMA foreign_key_check").fetchall()
                          if sqlite else [])
                if broken:
                    raise RuntimeError(f"the schema upgrade broke {len(broken)} foreign keys "
                                       f"(first: {broken[0]}); nothing was changed")
        finally:
            if sqlite:
                raw.execute("PRAGMA foreign_keys=ON")


def _check_schema(engine: Engine, shown: str) -> None:
    """Raise unless the database holds this swtlab's schema (at head)."""
    with engine.connect() as connection:
        current = MigrationContext.configure(connection).get_current_revision()
    head = head_revision()
    if current == head:
        return
    if current is None:
        raise UnusableDatabase(f"{shown}: holds no swtlab schema (create it with swtlab process "
                            f"CAMPAIGN --db URL or {UPGRADE_COMMAND})")
    known = {s.revision for s in ScriptDirectory.from_config(_config()).walk_revisions()}
    if current not in known:
        raise UnusableDatabase(f"{shown}: schema revision {current} is newer than this swtlab's "
                            f"{head}; upgrade swtlab to read it")
    raise UnusableDatabase(f"{shown}: schema revision {current} is older than this swtlab's {head};"
                        f" upgrade it with {UPGRADE_COMMAND} (or swtlab process, which does)")


def _connection_problem(error: DBAPIError, url: URL) -> str:
    """The driver's first line, without the password."""
    line = str(error.orig).strip().splitlines()[0] if error.orig else type(error).__name__
    if url.password:
        line = line.replace(str(url.password), "***")
    return line


def open_database(url: str, *, create: bool = True, read_only: bool = False
                  ) -> sessionmaker[Session]:
    """A session factory on the database at ``url`` (any SQLAlchemy URL, a plain path for
    SQLite, ``postgres://``).

    ``create`` (default): create the database file and upgrade the schema to head.
    ``create=False``: the database must exist at this swtlab's schema (writes allowed).
    ``read_only=True``: the same, without the write lock. Raises :class:`UnusableDatabase`."""
    try:
        parsed = make_url(database_url(url))
    except ArgumentError:
        raise UnusableDatabase(f"{url}: not a database URL (e.g. sqlite:///swtlab.sqlite, "
                            "postgresql://user@host/db, or a plain file path)") from None
    shown = _shown(parsed)
    create = create and not read_only
    path = _sqlite_file(parsed)
    if path is not None:
        if create:
            path.parent.mkdir(parents=True, exist_ok=True)
        elif not path.is_file():
            raise UnusableDatabase(f"{path}: no such database file (run swtlab process CAMPAIGN "
                                f"--db {url} first)")
    try:
        engine = _engine(parsed, writer=not read_only)
    except (ArgumentError, ImportError) as error:
        raise UnusableDatabase(f"{shown}: cannot use this URL ({error})") from None
    try:
        if create:
            upgrade(engine)
        _check_schema(engine, shown)
    except DBAPIError as error:
        engine.dispose()
        where = path if path is not None else f"{parsed.host or 'localhost'}" + (
            f":{parsed.port}" if parsed.port else "")
        raise UnusableDatabase(f"{shown}: cannot open the database at {where} "
                            f"({_connection_problem(error, parsed)})") from None
    return sessionmaker(engine, expire_on_commit=False)


def _retryable(error: DBAPIError) -> bool:
    """A lock, a busy database, a serialization failure or deadlock, or a unique key a
    concurrent writer took first: trying the transaction again can succeed."""
    code = getattr(error.orig, "sqlstate", None)
    text = str(error.orig).lower()
    if isinstance(error, IntegrityError):
        return code == "23505" or "unique constraint failed" in text
    return code in ("40001", "40P01", "55P03") or "locked" in text or "busy" in text


def in_transaction(factory: sessionmaker[Session], work: Callable[[Session], T], *,
                   attempts: int = 12) -> T:
    """``work(session)`` in one transaction, committed; a transaction that met a lock (or lost
    a unique key to a concurrent writer) is rolled back and tried again, with a randomised
    exponential backoff (0.05 s doubling up to 5 s)."""
    delay_s = 0.05
    for attempt in range(attempts):
        try:
            with factory.begin() as session:
                return work(session)
        except (OperationalError, IntegrityError) as error:
            unique = isinstance(error, IntegrityError)
            if attempt >= (2 if unique else attempts - 1) or not _retryable(error):
                raise
            time.sleep(delay_s * (1 + random.random()))
            delay_s = min(2 * delay_s, 5.0)
    raise AssertionError("unreachable")
