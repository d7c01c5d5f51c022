"""`python3 -m rubass …` runs the command line."""
import sys

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C while the modules load: as during a command, exit 130 quietly
    sys.exit(130)

sys.exit(main())
