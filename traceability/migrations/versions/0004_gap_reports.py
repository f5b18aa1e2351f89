"""gap reports

Revision ID: 0004
Revises: 0003
"""

from alembic import op
import sqlalchemy as sa


revision = '0004'
down_revision = '0003'
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table('gap_report',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('sim_source', sa.String(length=1000), nullable=False),
    sa.Column('verdict', sa.JSON(), nullable=False),
    sa.Column('report', sa.JSON(), nullable=False),
    sa.Column('processing_id', sa.Integer(), nullable=False),
    sa.ForeignKeyConstraint(['processing_id'], ['processing_record.id'], ),
    sa.PrimaryKeyConstraint('id')
    )


def downgrade() -> None:
    op.drop_table('gap_report')
