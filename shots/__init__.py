"""Shot records: the canonical CSV format, loaders for real launch-monitor exports, the reference world and
the synthetic session generator."""
