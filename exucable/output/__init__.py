"""What a run leaves behind: ``results`` (the documented files), ``snapshots`` (the state at chosen
times), ``formats`` (column tables and JSON Schemas), ``export`` (the discrete problem for another
solver), ``compare`` (two result directories against each other), ``versions`` (what made them)."""
