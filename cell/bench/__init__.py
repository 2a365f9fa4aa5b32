"""Speed figures (``cell bench``, ``make bench``)."""
