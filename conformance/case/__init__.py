"""What a case is and what it runs with: the @case decorator, the registry and the
context a case runs in (context.py), what a feature configured in EEPROM needs before a
case relies on it (preconditions.py), the Hypothesis settings of the machines and the
run's seed (settings.py)."""
