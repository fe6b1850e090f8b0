"""impactqp: rigid-body impacts as convex programs."""
