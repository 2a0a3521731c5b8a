"""One module per subcommand: argument parsing and printing only (``exucable/cli.py`` is the table)."""
