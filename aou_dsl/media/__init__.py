"""Pictures and videos of behaviours: plots, renders, study variant pairs."""
