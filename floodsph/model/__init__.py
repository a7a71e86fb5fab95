"""The particle model: its set-up, the state it steps, refinement and the stage timer."""
