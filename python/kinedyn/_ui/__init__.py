"""What kinedyn shows people: terminal tables that keep numbers whole (``terminal``), progress bars
for long work (``progress``) and values made fit for JSON (``json``). The ground floor of the layers
in docs/architecture.md: it imports nothing else of kinedyn."""
