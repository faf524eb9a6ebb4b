"""Models from the user's own files (``.brdf`` files, Python files): layer 2."""
