"""LIGGGHTS (`engine.py`): its normal model and its tangential history, one module each."""
