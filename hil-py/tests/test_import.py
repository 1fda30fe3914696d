import re

import hil


def test_version_is_the_workspace_version():
    assert re.fullmatch(r"\d+\.\d+\.\d+", hil.__version__)
