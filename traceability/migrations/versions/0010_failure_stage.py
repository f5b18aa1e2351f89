"""a failure's stage, exception type and run id, so failed runs can be listed

Revision ID: 0010
Revises: 0009
"""

from alembic import op
import sqlalchemy as sa


revision = '0010'
down_revision = '0009'
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table('ingest_failure') as batch:
        batch.add_column(sa.Column('stage', sa.String(length=20), nullable=False,
                                   server_default='ingest'))
        batch.add_column(sa.Column('error_type', sa.String(length=100), nullable=True))
        batch.add_column(sa.Column('run_id', sa.String(length=1000), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table('ingest_failure') as batch:
        batch.drop_column('run_id')
        batch.drop_column('error_type')
        batch.drop_column('stage')
