"""stable windows, run results, ingest failures

Revision ID: 0002
Revises: 0001
"""

from alembic import op
import sqlalchemy as sa


revision = '0002'
down_revision = '0001'
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table('ingest_failure',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('path', sa.String(length=1000), nullable=False),
    sa.Column('sha256', sa.String(length=64), nullable=False),
    sa.Column('error', sa.String(length=2000), nullable=False),
    sa.Column('processing_id', sa.Integer(), nullable=False),
    sa.ForeignKeyConstraint(['processing_id'], ['processing_record.id'], ),
    sa.PrimaryKeyConstraint('id')
    )
    op.create_table('stable_window',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('raw_file_id', sa.Integer(), nullable=False),
    sa.Column('found', sa.Boolean(), nullable=False),
    sa.Column('start_s', sa.Float(), nullable=True),
    sa.Column('end_s', sa.Float(), nullable=True),
    sa.Column('method', sa.String(length=200), nullable=False),
    sa.Column('parameters', sa.JSON(), nullable=False),
    sa.Column('diagnostics', sa.JSON(), nullable=False),
    sa.Column('reason', sa.String(length=1000), nullable=True),
    sa.Column('processing_id', sa.Integer(), nullable=False),
    sa.ForeignKeyConstraint(['processing_id'], ['processing_record.id'], ),
    sa.ForeignKeyConstraint(['raw_file_id'], ['raw_file.id'], ),
    sa.PrimaryKeyConstraint('id')
    )
    op.create_table('run_result',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('raw_file_id', sa.Integer(), nullable=False),
    sa.Column('stable_window_id', sa.Integer(), nullable=False),
    sa.Column('params_sha256', sa.String(length=64), nullable=False),
    sa.Column('status', sa.String(length=20), nullable=False),
    sa.Column('flags', sa.JSON(), nullable=False),
    sa.Column('oscillation', sa.JSON(), nullable=False),
    sa.Column('corrections', sa.JSON(), nullable=False),
    sa.Column('dp_trace', sa.JSON(), nullable=True),
    sa.Column('processing_id', sa.Integer(), nullable=False),
    sa.ForeignKeyConstraint(['processing_id'], ['processing_record.id'], ),
    sa.ForeignKeyConstraint(['raw_file_id'], ['raw_file.id'], ),
    sa.ForeignKeyConstraint(['stable_window_id'], ['stable_window.id'], ),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('raw_file_id', 'params_sha256')
    )
    op.create_table('run_quantity',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('run_result_id', sa.Integer(), nullable=False),
    sa.Column('quantity', sa.String(length=60), nullable=False),
    sa.Column('unit', sa.String(length=20), nullable=False),
    sa.Column('mean', sa.Float(), nullable=True),
    sa.Column('std', sa.Float(), nullable=True),
    sa.Column('se', sa.Float(), nullable=True),
    sa.Column('n', sa.Integer(), nullable=False),
    sa.Column('n_eff', sa.Float(), nullable=True),
    sa.ForeignKeyConstraint(['run_result_id'], ['run_result.id'], ),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('run_result_id', 'quantity')
    )


def downgrade() -> None:
    op.drop_table('run_quantity')
    op.drop_table('run_result')
    op.drop_table('stable_window')
    op.drop_table('ingest_failure')
