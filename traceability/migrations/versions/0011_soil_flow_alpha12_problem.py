"""why a soil flow's alpha1 and alpha2 are blank (eps_vol^P not resolvable to 0.01)

Revision ID: 0011
Revises: 0010
"""

from alembic import op
import sqlalchemy as sa


revision = '0011'
down_revision = '0010'
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table('soil_flow') as batch:
        batch.add_column(sa.Column('alpha12_problem', sa.String(length=2000), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table('soil_flow') as batch:
        batch.drop_column('alpha12_problem')
