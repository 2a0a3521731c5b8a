"""One module per subcommand: argument parsing and printing (``exucable/cli.py`` is the table)."""
