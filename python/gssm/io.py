"""Dataset folders as NumPy arrays: every layout gssm-process reads."""
from . import _gssm

Dataset = _gssm.io.Dataset
read_dataset = _gssm.io.read_dataset
write_dataset = _gssm.io.write_dataset
from_arrays = _gssm.io.from_arrays
scenarios = _gssm.io.scenarios
scenario_ini = _gssm.io.scenario_ini
ini_option_keys = _gssm.io.ini_option_keys
ini_reference = _gssm.io.ini_reference
__all__ = ["Dataset", "read_dataset", "write_dataset", "from_arrays", "scenarios", "scenario_ini", "ini_option_keys", "ini_reference"]
