"""One module per `uitamr` sub-command; each defines a click command named `command`."""
