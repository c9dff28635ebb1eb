"""Distilled relational models on the widened room knowledge, with the held-out-fitted room
blend (room_blend.json); written by `sgtool distill --room-blend`."""
