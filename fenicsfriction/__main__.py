import sys

from fenicsfriction import signals

# SIGINT/SIGTERM are a flag from here on, before the command line's imports (main catches
# them again, for the console script)
signals.catch()

from fenicsfriction.cli import main  # noqa: E402

sys.exit(main())
