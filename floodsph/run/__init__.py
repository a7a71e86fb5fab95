"""One run of a scenario: the pipeline, the run folder, run.json, results and the compile notice."""
