"""In-building delivery benchmark (PRS-style) on GSR building scene graphs: tasks, baseline, metrics."""
