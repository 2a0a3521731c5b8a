"""On site: a tension recorder's log read (``log``), the friction coefficient fitted to it against the
pull-in history with a block-bootstrap interval, the rest of the pull forecast (``friction``), a growing
log followed (``watch``), and synthetic logs with a known coefficient to check all of it (``synthetic``)."""
