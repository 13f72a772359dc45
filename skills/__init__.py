"""PyBullet world and meta-skill library (see ARCHITECTURE.md). Depends on `gsr` and `perception`."""
