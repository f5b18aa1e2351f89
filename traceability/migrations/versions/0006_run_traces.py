"""decimated channel traces of each run result (the report's time series)

Revision ID: 0006
Revises: 0005
"""

from alembic import op
import sqlalchemy as sa


revision = '0006'
down_revision = '0005'
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table('run_trace',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('run_result_id', sa.Integer(), nullable=False),
    sa.Column('channel', sa.String(length=60), nullable=False),
    sa.Column('unit', sa.String(length=20), nullable=False),
    sa.Column('samples', sa.Integer(), nullable=False),
    sa.Column('block', sa.Integer(), nullable=False),
    sa.Column('points', sa.Integer(), nullable=False),
    sa.Column('arrays', sa.LargeBinary(), nullable=False),
    sa.ForeignKeyConstraint(['run_result_id'], ['run_result.id'], ),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('run_result_id', 'channel')
    )


def downgrade() -> None:
    op.drop_table('run_trace')
