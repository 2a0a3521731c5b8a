"""The command line: one module per subcommand, each with ``add_arguments(parser)`` and
``main(args) -> int`` (the exit status). Only modules here print or choose an exit status; the
library below returns values and raises :class:`~exucable.errors.ExucableError`, which
:mod:`exucable.cli` (the subcommand table) turns into one line and exit status 2.
"""
