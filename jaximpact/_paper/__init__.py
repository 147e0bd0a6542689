"""The seed paper (Polukoshko et al. 2007) reproduced: its cases, tables and figures.
Imports the library layers below it; never the command line."""
