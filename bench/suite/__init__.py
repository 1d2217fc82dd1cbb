"""rtpg's benchmark suite: run time against error for path tracing and PMM path guiding."""
