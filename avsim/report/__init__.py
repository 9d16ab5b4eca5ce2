"""Reports: speed plots, JUnit, summary.md, sweep tables and heat maps."""
