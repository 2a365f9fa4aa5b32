"""Plumbing every layer uses: errors, output written whole or not at all, progress,
standard streams, interrupts, the disk cache."""
