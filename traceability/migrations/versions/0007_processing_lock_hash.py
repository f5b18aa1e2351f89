"""the sha256 of the lock file the environment was installed from, on each processing record

Revision ID: 0007
Revises: 0006
"""

from alembic import op
import sqlalchemy as sa


revision = '0007'
down_revision = '0006'
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table('processing_record') as batch:
        batch.add_column(sa.Column('lock_sha256', sa.String(length=64), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table('processing_record') as batch:
        batch.drop_column('lock_sha256')
