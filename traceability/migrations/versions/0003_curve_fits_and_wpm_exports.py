"""curve fits and WPM exports

Revision ID: 0003
Revises: 0002
"""

from alembic import op
import sqlalchemy as sa


revision = '0003'
down_revision = '0002'
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table('curve_fit',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('fit_sha256', sa.String(length=64), nullable=False),
    sa.Column('wheel', sa.String(length=200), nullable=False),
    sa.Column('soil', sa.String(length=200), nullable=False),
    sa.Column('multipass', sa.Integer(), nullable=False),
    sa.Column('load_n', sa.Float(), nullable=False),
    sa.Column('quantity', sa.String(length=40), nullable=False),
    sa.Column('unit', sa.String(length=20), nullable=False),
    sa.Column('degree', sa.Integer(), nullable=False),
    sa.Column('coefficients', sa.JSON(), nullable=False),
    sa.Column('slip_min', sa.Float(), nullable=False),
    sa.Column('slip_max', sa.Float(), nullable=False),
    sa.Column('n_points', sa.Integer(), nullable=False),
    sa.Column('rmse', sa.Float(), nullable=False),
    sa.Column('diagnostics', sa.JSON(), nullable=False),
    sa.Column('processing_id', sa.Integer(), nullable=False),
    sa.ForeignKeyConstraint(['processing_id'], ['processing_record.id'], ),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('fit_sha256')
    )
    op.create_table('wpm_export',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('path', sa.String(length=1000), nullable=False),
    sa.Column('file_sha256', sa.String(length=64), nullable=False),
    sa.Column('inputs_sha256', sa.String(length=64), nullable=False),
    sa.Column('format_version', sa.String(length=40), nullable=False),
    sa.Column('processing_id', sa.Integer(), nullable=False),
    sa.ForeignKeyConstraint(['processing_id'], ['processing_record.id'], ),
    sa.PrimaryKeyConstraint('id')
    )
    op.create_table('wpm_export_fit',
    sa.Column('wpm_export_id', sa.Integer(), nullable=False),
    sa.Column('curve_fit_id', sa.Integer(), nullable=False),
    sa.ForeignKeyConstraint(['curve_fit_id'], ['curve_fit.id'], ),
    sa.ForeignKeyConstraint(['wpm_export_id'], ['wpm_export.id'], ),
    sa.PrimaryKeyConstraint('wpm_export_id', 'curve_fit_id')
    )
    op.create_table('curve_fit_input',
    sa.Column('curve_fit_id', sa.Integer(), nullable=False),
    sa.Column('run_result_id', sa.Integer(), nullable=False),
    sa.ForeignKeyConstraint(['curve_fit_id'], ['curve_fit.id'], ),
    sa.ForeignKeyConstraint(['run_result_id'], ['run_result.id'], ),
    sa.PrimaryKeyConstraint('curve_fit_id', 'run_result_id')
    )


def downgrade() -> None:
    op.drop_table('curve_fit_input')
    op.drop_table('wpm_export_fit')
    op.drop_table('wpm_export')
    op.drop_table('curve_fit')
