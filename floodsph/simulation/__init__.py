"""The time loop: schedules, probes, recorders, checkpoints and stop signals."""
