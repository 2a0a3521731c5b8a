"""Validation suites: ``paper`` (the paper's examples against closed forms and the rope) and
``industry`` (published worked pulls)."""
