"""Model against measurement: compare, diagnose the missing effect, add it, watch the error fall."""
