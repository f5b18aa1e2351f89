"""raw files, runs, conditions, calibrations

Revision ID: 0001
Revises: 
"""

from alembic import op
import sqlalchemy as sa


revision = '0001'
down_revision = None
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table('campaign',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('name', sa.String(length=200), nullable=False),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('name')
    )
    op.create_table('processing_record',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('swtlab_version', sa.String(length=40), nullable=False),
    sa.Column('stage', sa.String(length=40), nullable=False),
    sa.Column('parameters', sa.JSON(), nullable=False),
    sa.Column('created_at', sa.DateTime(timezone=True), nullable=False),
    sa.PrimaryKeyConstraint('id')
    )
    op.create_table('soil',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('name', sa.String(length=200), nullable=False),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('name')
    )
    op.create_table('wheel',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('name', sa.String(length=200), nullable=False),
    sa.Column('radius_m', sa.Float(), nullable=False),
    sa.Column('width_m', sa.Float(), nullable=False),
    sa.Column('grouser_count', sa.Integer(), nullable=False),
    sa.Column('grouser_height_m', sa.Float(), nullable=False),
    sa.Column('stiffness_n_per_mm', sa.Float(), nullable=True),
    sa.Column('mass_kg', sa.Float(), nullable=True),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('name', 'radius_m', 'width_m', 'grouser_count', 'grouser_height_m', 'stiffness_n_per_mm')
    )
    op.create_table('test_condition',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('campaign_id', sa.Integer(), nullable=False),
    sa.Column('wheel_id', sa.Integer(), nullable=False),
    sa.Column('soil_id', sa.Integer(), nullable=False),
    sa.Column('mode', sa.String(length=20), nullable=False),
    sa.Column('multipass', sa.Integer(), nullable=False),
    sa.Column('load_n', sa.Float(), nullable=False),
    sa.Column('slip_setpoint', sa.Float(), nullable=True),
    sa.Column('velocity_mps', sa.Float(), nullable=False),
    sa.Column('gravity_mps2', sa.Float(), nullable=False),
    sa.Column('steer_deg', sa.Float(), nullable=True),
    sa.ForeignKeyConstraint(['campaign_id'], ['campaign.id'], ),
    sa.ForeignKeyConstraint(['soil_id'], ['soil.id'], ),
    sa.ForeignKeyConstraint(['wheel_id'], ['wheel.id'], ),
    sa.PrimaryKeyConstraint('id')
    )
    op.create_table('run',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('campaign_id', sa.Integer(), nullable=False),
    sa.Column('run_id', sa.String(length=200), nullable=False),
    sa.Column('condition_id', sa.Integer(), nullable=False),
    sa.Column('started_at', sa.DateTime(timezone=True), nullable=True),
    sa.ForeignKeyConstraint(['campaign_id'], ['campaign.id'], ),
    sa.ForeignKeyConstraint(['condition_id'], ['test_condition.id'], ),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('campaign_id', 'run_id')
    )
    op.create_table('raw_file',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('run_pk', sa.Integer(), nullable=False),
    sa.Column('version', sa.Integer(), nullable=False),
    sa.Column('path', sa.String(length=1000), nullable=False),
    sa.Column('size_bytes', sa.Integer(), nullable=False),
    sa.Column('sha256', sa.String(length=64), nullable=False),
    sa.Column('file_format', sa.String(length=40), nullable=False),
    sa.Column('channel_summary', sa.JSON(), nullable=False),
    sa.Column('problems', sa.JSON(), nullable=False),
    sa.Column('processing_id', sa.Integer(), nullable=False),
    sa.ForeignKeyConstraint(['processing_id'], ['processing_record.id'], ),
    sa.ForeignKeyConstraint(['run_pk'], ['run.id'], ),
    sa.PrimaryKeyConstraint('id'),
    sa.UniqueConstraint('run_pk', 'sha256'),
    sa.UniqueConstraint('run_pk', 'version')
    )
    op.create_table('calibration',
    sa.Column('id', sa.Integer(), nullable=False),
    sa.Column('raw_file_id', sa.Integer(), nullable=False),
    sa.Column('kind', sa.String(length=20), nullable=False),
    sa.Column('topic', sa.String(length=200), nullable=False),
    sa.Column('field', sa.String(length=100), nullable=False),
    sa.Column('gain', sa.Float(), nullable=False),
    sa.Column('offset', sa.Float(), nullable=False),
    sa.ForeignKeyConstraint(['raw_file_id'], ['raw_file.id'], ),
    sa.PrimaryKeyConstraint('id')
    )


def downgrade() -> None:
    op.drop_table('calibration')
    op.drop_table('raw_file')
    op.drop_table('run')
    op.drop_table('test_condition')
    op.drop_table('wheel')
    op.drop_table('soil')
    op.drop_table('processing_record')
    op.drop_table('campaign')
