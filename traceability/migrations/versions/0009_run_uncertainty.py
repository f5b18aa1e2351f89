"""uncertainty budget of each run quantity (run_results.uncertainty_budget)

Revision ID: 0009
Revises: 0008
"""

from alembic import op
import sqlalchemy as sa


revision = '0009'
down_revision = '0008'
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table('run_uncertainty',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('run_result_id', sa.Integer(), nullable=False),
    sa.Column('quantity', sa.String(length=60), nullable=False),
    sa.Column('unit', sa.String(length=20), nullable=False),
    sa.Column('correction', sa.Float(), nullable=True),
    sa.Column('u_statistical', sa.Float(), nullable=True),
    sa.Column('u_zero_drift', sa.Float(), nullable=True),
    sa.Column('u_calibration', sa.Float(), nullable=True),
    sa.Column('u_quantisation', sa.Float(), nullable=True),
    sa.Column('u_phase_sampling', sa.Float(), nullable=True),
    sa.Column('u_clock', sa.Float(), nullable=True),
    sa.Column('u', sa.Float(), nullable=True),
    sa.Column('dof', sa.Float(), nullable=True),
    sa.Column('k', sa.Float(), nullable=True),
    sa.Column('u95', sa.Float(), nullable=True),
    sa.Column('not_measured', sa.JSON(), nullable=False),
    sa.ForeignKeyConstraint(['run_result_id'], ['run_result.id'], ),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('run_result_id', 'quantity')
    )


def downgrade() -> None:
    op.drop_table('run_uncertainty')
