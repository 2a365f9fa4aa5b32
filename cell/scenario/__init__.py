"""The scenario: its schema and sections, reading YAML and trace files, --set
overrides, the built-in scenarios, the arrival distributions and the policy names."""
