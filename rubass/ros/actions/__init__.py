"""Action plugins (publish, serial, service, log, custom) and the runner that drives each."""
