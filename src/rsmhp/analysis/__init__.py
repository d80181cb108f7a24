"""Aggregation of raw experiment tables into summaries, Markdown tables and report sections."""
