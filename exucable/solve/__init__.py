"""The two ways of solving one model: ``dynamic`` (the paper's generalized-α integration), ``steady``
(the steady sliding state in one static solve) and ``start`` (a dynamic run started in the steady
state); ``pull_in``: the pull-in history as a sequence of steady solves."""
