"""Rerun recordings and static figures."""
