#!/usr/bin/env python3
"""A held-out LuxCoreRender animation in LuxCore's own layout: one numbered folder per frame with
RGB.exr, ALBEDO.exr, AVG_SHADING_NORMAL.exr, POSITION.exr and DEPTH.exr, and no motion vectors
(LuxCore writes none); a camera swings 57 degrees around a glass sphere, a gold sphere and a box.

    python -m venv /tmp/luxvenv && /tmp/luxvenv/bin/pip install pyluxcore numpy   # Python 3.11 wheel
    /tmp/luxvenv/bin/python scripts/corpus/luxcore_sequence.py out/luxcore_seq --spp 1 --ref-spp 1024
    /tmp/luxvenv/bin/python scripts/corpus/luxcore_sequence.py out/luxcore_seq --spp 4 --ref-spp 0

writes OUT/frames_sNNNN/0000/ ... (the noisy frames at --spp) and OUT/ref/0000/ ... (the reference,
skipped when there). Then `atrous denoise --sequence OUT/frames_s0001 --out DIR` and `atrous compare
--sequence OUT/ref DIR` (docs/temporal.md, "A LuxCore sequence"). About 16 s per 1024-spp frame
at 96x96 on 2 cores. Not part of `make test`: pyluxcore is not a project dependency.
"""
import argparse
import math
import os
import time

import pyluxcore
pyluxcore.Init(lambda s: None)
def box(cx,cy,cz,sx,sy,sz):
    v=[(cx+sx*x,cy+sy*y,cz+sz*z) for x in (-1,1) for y in (-1,1) for z in (-1,1)]
    f=[(0,1,3),(0,3,2),(4,6,7),(4,7,5),(0,4,5),(0,5,1),(2,3,7),(2,7,6),(0,2,6),(0,6,4),(1,5,7),(1,7,3)]
    return v,f
def sphere(cx,cy,cz,r,n=24):
    v=[];f=[]
    for i in range(n+1):
        th=math.pi*i/n
        for j in range(2*n):
            ph=2*math.pi*j/(2*n); v.append((cx+r*math.sin(th)*math.cos(ph),cy+r*math.cos(th),cz+r*math.sin(th)*math.sin(ph)))
    for i in range(n):
        for j in range(2*n):
            a=i*2*n+j; b=i*2*n+(j+1)%(2*n); c=a+2*n; d=b+2*n; f+= [(a,c,b),(b,c,d)]
    return v,f
def render(out, frame, nframes, spp, seed, size=128):
    scene=pyluxcore.Scene()
    ang=-0.5+1.0*frame/max(nframes-1,1)
    orig=(6*math.sin(ang),2.2,6*math.cos(ang))
    p=pyluxcore.Properties()
    p.Set(pyluxcore.Property("scene.camera.type","perspective"))
    p.Set(pyluxcore.Property("scene.camera.lookat.orig",list(orig)))
    p.Set(pyluxcore.Property("scene.camera.lookat.target",[0,0.8,0]))
    p.Set(pyluxcore.Property("scene.camera.up",[0,1,0]))
    p.Set(pyluxcore.Property("scene.camera.fieldofview",45))
    mats={"white":("matte",{"kd":[0.7,0.7,0.7]}),"red":("matte",{"kd":[0.7,0.15,0.1]}),
          "glass":("glass",{"kr":[1,1,1],"kt":[1,1,1],"interiorior":1.5}),
          "gold":("metal2",{"preset":"gold","uroughness":0.08,"vroughness":0.08}),
          "light":("matte",{"kd":[0,0,0],"emission":[12,12,12]})}
    for m,(t,kv) in mats.items():
        p.Set(pyluxcore.Property(f"scene.materials.{m}.type",t))
        for k,v in kv.items(): p.Set(pyluxcore.Property(f"scene.materials.{m}.{k}",v))
    scene.Parse(p)
    shapes={"floor":(box(0,-0.05,0,5,0.05,5),"white"),"wall":(box(0,2,-3,5,2,0.1),"red"),
            "cube":(box(-1.2,0.5,0.3,0.5,0.5,0.5),"white"),"ball":(sphere(1.0,0.7,0.2,0.7),"glass"),
            "gold":(sphere(0.0,0.5,-1.3,0.5),"gold"),"lamp":(box(0,3.8,0,1.0,0.02,1.0),"light")}
    p=pyluxcore.Properties()
    for n,((v,f),m) in shapes.items():
        scene.DefineMesh(n+"_m",v,f,None,None,None,None)
        p.Set(pyluxcore.Property(f"scene.objects.{n}.shape",n+"_m"))
        p.Set(pyluxcore.Property(f"scene.objects.{n}.material",m))
    p.Set(pyluxcore.Property("scene.lights.sky.type","constantinfinite"))
    p.Set(pyluxcore.Property("scene.lights.sky.color",[0.15,0.18,0.25]))
    scene.Parse(p)
    c=pyluxcore.Properties()
    for k,v in {"renderengine.type":"PATHCPU","sampler.type":"RANDOM","batch.haltspp":spp,"film.width":size,"film.height":size,
                "path.pathdepth.total":8,"film.filter.type":"BLACKMANHARRIS","native.threads.count":2,"renderengine.seed":seed,
                "film.imagepipelines.0.0.type":"NOP"}.items():
        c.Set(pyluxcore.Property(k,v))
    os.makedirs(out,exist_ok=True)
    for i,t in enumerate(["RGB","ALBEDO","AVG_SHADING_NORMAL","POSITION","DEPTH"]):
        c.Set(pyluxcore.Property(f"film.outputs.{i}.type",t)); c.Set(pyluxcore.Property(f"film.outputs.{i}.filename",os.path.join(out,t+".exr")))
    cfg=pyluxcore.RenderConfig(c,scene); s=pyluxcore.RenderSession(cfg); s.Start()
    while not s.HasDone(): time.sleep(0.05); s.UpdateStats()
    s.Stop(); s.GetFilm().SaveOutputs()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1)
    ap.add_argument("--ref-spp", type=int, default=1024, help="0: no reference")
    ap.add_argument("--frames", type=int, default=12)
    ap.add_argument("--size", type=int, default=96)
    a = ap.parse_args()
    t0 = time.time()
    for f in range(a.frames):
        render(f"{a.out}/frames_s{a.spp:04d}/{f:04d}", f, a.frames, a.spp, 1 + 1000 * a.spp + f, a.size)
        if a.ref_spp and not os.path.exists(f"{a.out}/ref/{f:04d}/RGB.exr"):
            render(f"{a.out}/ref/{f:04d}", f, a.frames, a.ref_spp, 900001 + f, a.size)
        print(f"frame {f}: {time.time() - t0:.1f} s", flush=True)
    os._exit(0)  # pyluxcore's log callback crashes at interpreter shutdown


if __name__ == "__main__":
    main()
