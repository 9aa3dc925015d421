"""The records table: one row per result about a unit, never updated.

Revision ID: 0001
Revises:
Create Date: 2025-01-01
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

from gyrocal.store.schema import DOCUMENT, UTCDateTime

revision = "0001"
down_revision = None
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "records",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("serial", sa.Text, nullable=False),
        sa.Column("kind", sa.Text, nullable=False),
        sa.Column("created", UTCDateTime(), nullable=False),
        sa.Column("station", sa.Text, nullable=True),
        sa.Column("operator", sa.Text, nullable=True),
        sa.Column("verdict", sa.String(4), nullable=True),
        sa.Column("input_sha256", sa.JSON, nullable=True),
        sa.Column("input_sha256_key", sa.Text, nullable=True),
        sa.Column("job", sa.Text, nullable=True),
        sa.Column("args", sa.Text, nullable=True),
        sa.Column("document", DOCUMENT, nullable=False),
        sa.CheckConstraint("verdict IN ('pass', 'fail')", name="ck_records_verdict"),
    )
    op.create_index("ix_records_serial_created", "records", ["serial", "created"])
    op.create_index("ix_records_created", "records", ["created"])
    op.create_index("ix_records_station", "records", ["station"])
    op.create_index("ix_records_verdict", "records", ["verdict"])
    op.create_index("ix_records_input_sha256_key", "records", ["input_sha256_key"])
    _append_only()


def _append_only() -> None:
    """Triggers that refuse UPDATE and DELETE on records: the store only ever appends."""
    if op.get_bind().dialect.name == "postgresql":
        op.execute("CREATE FUNCTION gyrocal_records_append_only() RETURNS trigger LANGUAGE plpgsql AS $$ "
                   "BEGIN RAISE EXCEPTION 'gyrocal records are append-only: % refused', TG_OP; END $$")
        op.execute("CREATE TRIGGER records_append_only BEFORE UPDATE OR DELETE ON records "
                   "FOR EACH ROW EXECUTE FUNCTION gyrocal_records_append_only()")
        return
    for action in ("UPDATE", "DELETE"):
        op.execute(f"CREATE TRIGGER records_no_{action.lower()} BEFORE {action} ON records "
                   f"BEGIN SELECT RAISE(ABORT, 'gyrocal records are append-only: {action} refused'); END")


def downgrade() -> None:
    op.drop_table("records")
    if op.get_bind().dialect.name == "postgresql":
        op.execute("DROP FUNCTION gyrocal_records_append_only()")
