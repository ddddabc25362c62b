"""`neepp view`: says what its Python lacks before importing it, then runs the command line."""
import sys

from ..requirements import VIEW_REQUIRED, require, require_package

require("neepp view", VIEW_REQUIRED)
require_package("neepp view")

from .cli import main  # noqa: E402

sys.exit(main())
