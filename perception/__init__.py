"""RGB-D to grounded scene graph (see ARCHITECTURE.md). Depends on `gsr` only."""
