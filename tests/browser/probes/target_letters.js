// The letters the task panel writes beside its targets, in the order of the targets.
(id) => document.getElementById(id).data.find((d) => d.name === "targets").text
