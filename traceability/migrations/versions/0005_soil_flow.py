"""soil flow results, their per-angle fits, flow failures

Revision ID: 0005
Revises: 0004
"""

from alembic import op
import sqlalchemy as sa


revision = '0005'
down_revision = '0004'
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table('soil_flow_failure',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('raw_file_id', sa.Integer(), nullable=False),
    sa.Column('params_sha256', sa.String(length=64), nullable=False),
    sa.Column('channel', sa.String(length=200), nullable=False),
    sa.Column('problem', sa.String(length=2000), nullable=False),
    sa.Column('processing_id', sa.Integer(), nullable=False),
    sa.ForeignKeyConstraint(['processing_id'], ['processing_record.id'], ),
    sa.ForeignKeyConstraint(['raw_file_id'], ['raw_file.id'], ),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('raw_file_id', 'params_sha256')
    )
    op.create_table('soil_flow',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('raw_file_id', sa.Integer(), nullable=False),
    sa.Column('stable_window_id', sa.Integer(), nullable=False),
    sa.Column('params_sha256', sa.String(length=64), nullable=False),
    sa.Column('frame_first', sa.Integer(), nullable=False),
    sa.Column('frame_last', sa.Integer(), nullable=False),
    sa.Column('t_first_s', sa.Float(), nullable=False),
    sa.Column('t_last_s', sa.Float(), nullable=False),
    sa.Column('pairs', sa.Integer(), nullable=False),
    sa.Column('engine', sa.String(length=40), nullable=False),
    sa.Column('px_per_m', sa.Float(), nullable=False),
    sa.Column('sled_velocity_x_mps', sa.Float(), nullable=False),
    sa.Column('sled_velocity_y_mps', sa.Float(), nullable=False),
    sa.Column('outlier_fraction', sa.Float(), nullable=False),
    sa.Column('wheel_center_x_px', sa.Float(), nullable=False),
    sa.Column('wheel_center_y_px', sa.Float(), nullable=False),
    sa.Column('wheel_radius_px', sa.Float(), nullable=False),
    sa.Column('grouser_model', sa.String(length=40), nullable=True),
    sa.Column('grouser_margin_percent', sa.Float(), nullable=True),
    sa.Column('grouser_gamma', sa.Float(), nullable=True),
    sa.Column('alpha1_per_m', sa.Float(), nullable=True),
    sa.Column('alpha2', sa.Float(), nullable=True),
    sa.Column('result', sa.JSON(), nullable=False),
    sa.Column('field_npz', sa.LargeBinary(), nullable=False),
    sa.Column('processing_id', sa.Integer(), nullable=False),
    sa.ForeignKeyConstraint(['processing_id'], ['processing_record.id'], ),
    sa.ForeignKeyConstraint(['raw_file_id'], ['raw_file.id'], ),
    sa.ForeignKeyConstraint(['stable_window_id'], ['stable_window.id'], ),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('raw_file_id', 'params_sha256')
    )
    op.create_table('soil_flow_fit',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('soil_flow_id', sa.Integer(), nullable=False),
    sa.Column('beta_deg', sa.Float(), nullable=False),
    sa.Column('component', sa.String(length=10), nullable=False),
    sa.Column('amplitude_mps', sa.Float(), nullable=False),
    sa.Column('rate_per_m', sa.Float(), nullable=False),
    sa.Column('ci95_low_per_m', sa.Float(), nullable=True),
    sa.Column('ci95_high_per_m', sa.Float(), nullable=True),
    sa.Column('r2', sa.Float(), nullable=True),
    sa.Column('points', sa.Integer(), nullable=False),
    sa.ForeignKeyConstraint(['soil_flow_id'], ['soil_flow.id'], ),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('soil_flow_id', 'beta_deg', 'component')
    )


def downgrade() -> None:
    op.drop_table('soil_flow_fit')
    op.drop_table('soil_flow')
    op.drop_table('soil_flow_failure')
