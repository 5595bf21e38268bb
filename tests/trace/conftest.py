import pytest
from _trace_lenses import dgauss_lens


@pytest.fixture(scope="session")
def dgauss():
    return dgauss_lens()
