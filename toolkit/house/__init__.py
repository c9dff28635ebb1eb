"""The house spec: the versioned ``house.json`` every log carries (rooms, walls, doors,
passages, furniture, small objects, start pose), its parsing and validation."""
