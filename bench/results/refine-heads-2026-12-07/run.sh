#!/bin/sh
# issue 47's head comparison: equal steps from scratch, run C's data and loss
cd /work/wt/still
for h in residual kernel direct; do
  .venv-train/bin/python scripts/train/refine.py train out/refine/train.npz,out/refine/corpus_train.npz:4 out/refine/heads/$h \
     --steps 3000 --minutes 60 --head $h --lr 1e-3 --mse 1 --energy 2 --seed 1 > out/refine/heads/$h.log 2>&1
  .venv-train/bin/python scripts/train/refine.py eval out/refine/test.npz out/refine/heads/$h > out/refine/heads/$h.eval 2>&1
done
