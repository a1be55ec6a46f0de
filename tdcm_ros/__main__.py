"""``python3 -m tdcm_ros COMMAND``: the ``tdcm`` command without relying on the scripts directory."""

import sys

from tdcm_ros.cli.main import main

sys.exit(main())
