"""LAMMPS (`engine.py`): its normal and tangential models, one module each."""
