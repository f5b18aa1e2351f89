"""the raw-file version each run's results come from, files found missing, and user text
(names up to 1,000 characters, paths up to 4,096) that every backend holds alike

Revision ID: 0008
Revises: 0007
"""

from alembic import op
import sqlalchemy as sa


revision = '0008'
down_revision = '0007'
branch_labels = None
depends_on = None

#: (table, column, old length, new length)
WIDENED = [
    ('campaign', 'name', 200, 1000), ('wheel', 'name', 200, 1000), ('soil', 'name', 200, 1000),
    ('run', 'run_id', 200, 1000), ('raw_file', 'path', 1000, 4096),
    ('raw_file', 'file_format', 40, 1000), ('calibration', 'topic', 200, 1000),
    ('calibration', 'field', 100, 1000), ('ingest_failure', 'path', 1000, 4096),
    ('curve_fit', 'wheel', 200, 1000), ('curve_fit', 'soil', 200, 1000),
    ('wpm_export', 'path', 1000, 4096), ('gap_report', 'sim_source', 1000, 4096),
    ('soil_flow_failure', 'channel', 200, 1000),
]


def _resize(widen: bool) -> None:
    """Every column of WIDENED to its new length (``widen``) or back to its old one."""
    tables = {}
    for table, column, before, after in WIDENED:
        tables.setdefault(table, []).append((column, before, after) if widen
                                            else (column, after, before))
    for table, columns in tables.items():
        with op.batch_alter_table(table) as batch:
            for column, now, then in columns:
                batch.alter_column(column, type_=sa.String(length=then),
                                   existing_type=sa.String(length=now), existing_nullable=False)


def upgrade() -> None:
    with op.batch_alter_table('run') as batch:
        batch.add_column(sa.Column('current_version', sa.Integer(), nullable=True))
    op.execute('UPDATE run SET current_version = (SELECT max(raw_file.version) FROM raw_file '
               'WHERE raw_file.run_pk = run.id)')
    op.execute('UPDATE run SET current_version = 1 WHERE current_version IS NULL')
    with op.batch_alter_table('run') as batch:
        batch.alter_column('current_version', existing_type=sa.Integer(), nullable=False)
    with op.batch_alter_table('raw_file') as batch:
        batch.add_column(sa.Column('missing_since', sa.DateTime(timezone=True), nullable=True))
    _resize(widen=True)


def downgrade() -> None:
    _resize(widen=False)
    with op.batch_alter_table('raw_file') as batch:
        batch.drop_column('missing_since')
    with op.batch_alter_table('run') as batch:
        batch.drop_column('current_version')
