"""Minimum-time motion along the transfer path (Shin & McKay 1983; SPEC §9)."""
