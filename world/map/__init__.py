"""Map builders: route roads, the town; signal timing."""
