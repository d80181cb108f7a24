"""The horizon study."""
