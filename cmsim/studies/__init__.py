"""Reproducible studies from the source papers (each module documents its paper section)."""
