"""Writes gssm/models.pyi from models.pyi.in and the model registry: one
class stub per registered model type, its keywords from the type's
parameters (docs/DESIGN.md §3, "Adding a model"). Run by the build:
    python3 -m gssm._stubgen <template> <output>
"""
import sys

from . import models

_ANNOTATION = {
    "real": "float", "flag": "bool", "text": "str", "names": "Union[Sequence[str], str]",
    "vector": "ArrayLike", "matrix": "ArrayLike", "table": "ArrayLike",
    "sections": "Sequence[Dict[str, object]]", "any": "Union[ArrayLike, str]",
}
_MARKER = "# @REGISTERED_MODEL_TYPES@"


def class_stub(info):
    args = []
    for p in info["params"]:
        default = "" if p["required"] else " = ..."
        args.append("%s: %s%s" % (p["name"], _ANNOTATION[p["kind"]], default))
    lines = ["class %s:" % info["class_name"],
             '    """%s"""' % info["summary"].replace('"""', "'''"),
             "    def __new__(cls, *, %s) -> Model: ..." % ", ".join(args)]
    return "\n".join(lines) + "\n"


def stubs(template):
    marker = next(line for line in template.splitlines() if line.startswith(_MARKER))
    classes = "\n".join(class_stub(t) for t in models.registered_types())
    return template.replace(marker, classes.rstrip() + "\n")


def main(argv):
    template, output = argv[1], argv[2]
    with open(template) as f:
        text = stubs(f.read())
    with open(output, "w") as f:
        f.write(text)


if __name__ == "__main__":
    main(sys.argv)
