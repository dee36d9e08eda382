robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage a extends c { module m { sense ir behavior forward } }
stage b extends a { module n { sense ir behavior back } }
stage c extends b { module o { sense ir behavior stop } }
stage d extends d { module p { sense ir behavior stop } }
