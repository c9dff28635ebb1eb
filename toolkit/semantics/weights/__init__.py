"""Shipped weights of the distilled relational models (safetensors + metadata.json)."""
