"""the rates' time-stamp term of the uncertainty budget (u_timing)

Revision ID: 0012
Revises: 0011
"""

from alembic import op
import sqlalchemy as sa


revision = '0012'
down_revision = '0011'
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table('run_uncertainty') as batch:
        batch.add_column(sa.Column('u_timing', sa.Float(), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table('run_uncertainty') as batch:
        batch.drop_column('u_timing')
