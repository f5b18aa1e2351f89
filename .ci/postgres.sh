#!/usr/bin/env bash
# Start a throw-away PostgreSQL server from Debian's packages for the database tests.
# Usage: source .ci/postgres.sh   -> exports SWTLAB_TEST_POSTGRES_URL, stops the server on exit.
set -euo pipefail
if ! ls /usr/lib/postgresql/*/bin/initdb >/dev/null 2>&1; then
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq postgresql >/dev/null
fi
PG_BIN=$(ls -d /usr/lib/postgresql/*/bin | sort -V | tail -n 1)
PG_DIR=$(mktemp -d /tmp/swtlab-pg.XXXXXX)
PG_PORT=${SWTLAB_PG_PORT:-54329}
RUN_AS=()
if [ "$(id -u)" = 0 ]; then  # the server refuses to run as root
    chown postgres "$PG_DIR"
    RUN_AS=(runuser -u postgres --)
fi
"${RUN_AS[@]}" "$PG_BIN/initdb" -D "$PG_DIR/data" -A trust -U postgres >/dev/null
"${RUN_AS[@]}" "$PG_BIN/pg_ctl" -D "$PG_DIR/data" -l "$PG_DIR/log" -w \
    -o "-p $PG_PORT -k $PG_DIR -c listen_addresses=127.0.0.1" start >/dev/null
stop_postgres() { "${RUN_AS[@]}" "$PG_BIN/pg_ctl" -D "$PG_DIR/data" -m fast stop >/dev/null || true; }
trap stop_postgres EXIT
export SWTLAB_TEST_POSTGRES_URL="postgresql+psycopg://postgres@127.0.0.1:$PG_PORT/postgres"
echo "PostgreSQL $("$PG_BIN/postgres" --version | awk '{print $3}') for the database tests at $SWTLAB_TEST_POSTGRES_URL"
