"""Pull planning for installation engineers: ``pull`` (both directions, limits, several cables) and
``report`` (the HTML report)."""
