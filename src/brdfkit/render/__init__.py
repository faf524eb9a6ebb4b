"""Rendering: the sphere test configuration and Monte-Carlo renders through Mitsuba 3."""
