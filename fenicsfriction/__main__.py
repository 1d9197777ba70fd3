import sys

from fenicsfriction.cli import main

sys.exit(main())
